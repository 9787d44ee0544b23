"""Fixtures of the unit tests."""
import functools

import pytest


@functools.cache
def _domain_id():
    # One ROS_DOMAIN_ID of the shared lease scheme for this pytest process (held until it ends).
    from mission.domain import lease_domain_id
    return lease_domain_id()


@pytest.fixture
def make_node():
    """make(**parameter_overrides) -> (rclpy node, NodeParameters) in a private context."""
    import rclpy
    from rclpy.context import Context
    from rclpy.parameter import Parameter

    from ship_sim.ros.params import NodeParameters
    ctx = Context()
    rclpy.init(context=ctx, domain_id=_domain_id())
    nodes = []

    def make(**overrides):
        node = rclpy.create_node(f'params_test_{len(nodes)}', context=ctx,
                                 parameter_overrides=[Parameter(k, value=v)
                                                      for k, v in overrides.items()])
        nodes.append(node)
        return node, NodeParameters(node)

    yield make
    for node in nodes:
        node.destroy_node()
    ctx.try_shutdown()
