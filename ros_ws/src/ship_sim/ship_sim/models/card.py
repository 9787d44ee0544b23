"""The vessel card: every fact about one plant model that the rest of shipnav needs.

A model's module defines its card (``CARD``, or ``CARDS`` for several) next to the model
class; ``ship_sim.models`` registers the cards of its own modules, of the modules named in
``SHIPNAV_EXTRA_CARDS`` and of any ``register_card`` call. Consumers (vessel_node, the
autopilot's gain design, wind, waves, the learning environment, the identification and the
scripts) read the card instead of keeping their own tables keyed by model name.

Facts that follow from the model itself (length, rudder and shaft limits, service speed) are
read from the model built with its defaults, so they are stated in one place only; big data
stays where it is and the card names it (the RAO table, the gain tables, the policy file).
This module is pure Python: it imports neither rclpy nor ship_autopilot.
"""
from dataclasses import dataclass, field
from functools import cached_property
from types import MappingProxyType

#: The vessel_node parameters a model may take (node parameter -> constructor keyword).
NODE_PARAMETERS = ('preset', 'nominal_speed_mps', 'water_depth_m')


@dataclass(frozen=True)
class VesselCard:
    """One vessel model's card (see the module docstring).

    name: registry name (the ``model`` parameter of the nodes, ``model:`` in scenarios).
    model: the VesselModel subclass.
    node_kwargs: vessel_node parameter (NODE_PARAMETERS) -> constructor keyword; a node
        parameter left at its default (0 or '') is not passed, and a non-default one the
        model does not take is refused.
    kinds: labels the scripts select models by (``model_names(kind=...)``): 'ship' (a ship,
        not the AUV), 'mss' (the MSS ship models: shaft or nominal speed, external loads),
        'nomoto' (linear Nomoto models).
    Loa, beam: length over all and beam (m), None if not stated (AIS static data falls back
        to the model's length).
    wind: the ship_sim.environment.wind.WindProfile, None if the model has no wind loads.
    rao: (RAO table name of ship_sim.environment.wave_rao, Froude-scale it to the model's
        length?), None if the model has no wave motion.
    omega_n_nd: nondimensional closed-loop natural frequency wn L / U of the heading autopilot
        design (ship_autopilot.gains); ``omega_n_nd_reason`` says why this value.
    identify: scripts/identify_nomoto.py fits this model when run without --models.
    gain_tables: folder holding the nomoto_gains.yaml and autopilot_gains.yaml entries of
        this model (the Nomoto fit and the designed gains); None = ship_autopilot's package
        data.
    nominal_curve: (amplitude m, wavelength m) of the learning environment's curved paths
        (as scenarios/routes/curved_path_<name>_000.yaml); None = the Mariner's.
    policy: file name of the shipped learned policy in ship_autopilot/data/policies, None if
        there is none.
    """
    name: str
    model: type
    node_kwargs: dict = field(default_factory=dict)
    kinds: frozenset = frozenset()
    Loa: float = None
    beam: float = None
    wind: object = None
    rao: tuple = None
    omega_n_nd: float = 1.0
    omega_n_nd_reason: str = ''
    identify: bool = True
    gain_tables: str = None
    nominal_curve: tuple = None
    policy: str = None

    def __post_init__(self):
        bad = set(self.node_kwargs) - set(NODE_PARAMETERS)
        if bad:
            raise ValueError(f'card {self.name!r}: node_kwargs keys {sorted(bad)} are not '
                             f'vessel_node parameters ({", ".join(NODE_PARAMETERS)})')
        # Read-only views: a card is shared by every consumer.
        object.__setattr__(self, 'node_kwargs', MappingProxyType(dict(self.node_kwargs)))
        object.__setattr__(self, 'kinds', frozenset(self.kinds))

    def make(self, **params):
        """The model with constructor keywords ``params`` (its defaults for the rest)."""
        return self.model(**params)

    @cached_property
    def default_model(self):
        """The model built with its defaults: the source of the derived facts below."""
        return self.model()

    @property
    def Lpp(self):
        """Length between perpendiculars (m)."""
        return float(self.default_model.length)

    @property
    def rudder_max(self):
        """Rudder angle limit (rad)."""
        return float(self.default_model.rudder_max)

    @property
    def rudder_rate_max(self):
        """Rudder rate limit (rad/s)."""
        return float(self.default_model.rudder_rate_max)

    @property
    def shaft_max(self):
        """Shaft speed limit (rpm), None for a model without a shaft."""
        m = self.default_model
        return float(m.shaft_max) if m.has_shaft else None

    @property
    def service_speed(self):
        """Speed through the water of the default straight-running state (m/s)."""
        m = self.default_model
        return float(m.speed(m.initial_state()))

    @property
    def has_wind(self):
        """True if the model takes wind loads (a profile and external loads)."""
        return self.wind is not None and bool(self.model.takes_external_loads)

    @property
    def has_waves(self):
        """True if the model has wave-frequency motion (an RAO table)."""
        return self.rao is not None


#: Why the ships' heading autopilots use wn' = 1.0 (ship_autopilot.gains).
SHIP_OMEGA_N_ND_REASON = (
    "the closed-loop frequency usual for ship autopilots: it satisfies Fossen's bandwidth rule "
    '1/T < wn for the identified T of every ship and gives k1 of order 1 (one degree of rudder '
    'per degree of heading error), so the PD stays inside the rudder and rudder-rate limits '
    'for small errors, which a larger wn would not')
