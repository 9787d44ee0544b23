"""The collision-avoidance methods by name (what the node's ``method`` parameter selects)."""
from ship_guidance.sbmpc import SBMPC
from ship_guidance.velocity_obstacles import VelocityObstacles

#: Method name -> class (a ship_guidance.colav.CollisionAvoidance).
METHODS = {cls.method: cls for cls in (SBMPC, VelocityObstacles)}


def make_colav(method, params=None, ship=None):
    """A collision-avoidance object: 'sbmpc' or 'vo', with ColavParams and an OwnShipModel
    (defaults when None)."""
    if method not in METHODS:
        raise ValueError(f'method = {method!r} is not allowed; allowed: {", ".join(METHODS)}')
    return METHODS[method](params, ship)
