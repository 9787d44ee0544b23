"""The parameter schema of a node: one declarative table per node, pure (no rclpy).

Each package has a ``schema`` module (``ship_sim.schema``, ``ship_guidance.schema``, ...) whose
``SCHEMAS`` maps every node executable to its NodeSchema. Everything about a node's parameters
is read from there:

- the node declares them (ship_sim.ros.params.NodeParameters.param / declare_schema);
- ``scripts/gen_param_files.py`` writes each package's config/<node>.yaml from it;
- the launcher checks scenario keys and values against it before anything starts
  (ship_mission.launcher.node_parameter_names, ship_mission.node_checks);
- the documentation's parameter reference (doc/guide/parameters.md) is rendered from it.

The value checks here (``problem``) are the ones NodeParameters applies to start values and
runtime changes, so a program that refuses a value before the node starts refuses exactly what
the node would.
"""
import importlib
import math
from dataclasses import dataclass, field

#: Parameter types: the Python type of a scalar, or a list of one (a ROS array parameter).
TYPES = ('bool', 'int', 'float', 'str', 'float[]', 'str[]')
_SCALAR = {'bool': bool, 'int': int, 'float': float, 'str': str}


@dataclass(frozen=True)
class Param:
    """One parameter of a node.

    type: one of TYPES (``Param.of`` infers it from the default); lo/hi: inclusive bounds of a
    number (published as the descriptor's range); choices: the allowed strings; check: the name
    of an extra check (a function value -> None or a short text of what is allowed) in the
    NodeSchema's ``checks`` or given by the node, for conditions a range cannot express;
    allowed: the text shown when a check fails, instead of one made from the range;
    allow_nonfinite: a float may be nan/inf (e.g. nan for 'not given'); deprecated_names: old
    names still accepted for one release, with a warning.
    """
    name: str
    type: str
    default: object
    description: str
    unit: str = ''
    lo: object = None
    hi: object = None
    choices: tuple = None
    read_only: bool = False
    check: str = None
    allowed: str = None
    allow_nonfinite: bool = False
    deprecated_names: tuple = ()

    def __post_init__(self):
        if self.type not in TYPES:
            raise TypeError(f'parameter {self.name!r}: unsupported type {self.type!r}')

    @classmethod
    def of(cls, name, default, description, **kw):
        """A scalar parameter whose type is that of ``default``."""
        kind = type(default).__name__
        if kind not in _SCALAR:
            raise TypeError(f'parameter {name!r}: unsupported default type {kind}')
        return cls(name, kind, default, description, **kw)

    @property
    def kind(self):
        """The Python type of the value (of an element for a list)."""
        return _SCALAR[self.type.removesuffix('[]')]

    @property
    def is_list(self):
        return self.type.endswith('[]')

    def allowed_text(self):
        """What is allowed, in words (the end of a refusal)."""
        if self.allowed is not None:
            return self.allowed
        return allowed_text(self.kind, self.lo, self.hi, self.choices)


@dataclass(frozen=True)
class NodeSchema:
    """The parameters of one node executable, in declaration order.

    checks: named extra checks the schema's parameters refer to (pure functions); a check
    that needs the running node (another parameter's value, a file search path) is given by
    the node when it declares and is skipped by pre-launch checks. config_values: values the
    package's config file sets instead of the defaults (e.g. use_sim_time, an example chart).
    """
    package: str
    node: str
    params: tuple
    checks: dict = field(default_factory=dict)
    config_values: dict = field(default_factory=dict)
    summary: str = ''

    def __post_init__(self):
        names = [p.name for p in self.params]
        if len(set(names)) != len(names):
            raise ValueError(f'{self.node}: a parameter is listed twice')

    @property
    def config_name(self):
        """The package's config file of the node: ``vessel_node`` -> ``vessel.yaml``."""
        return self.node.removesuffix('_node') + '.yaml'

    def names(self):
        return [p.name for p in self.params]

    def __getitem__(self, name):
        for p in self.params:
            if p.name == name:
                return p
        raise KeyError(name)

    def renamed(self):
        """{old name: current name} of the deprecated names."""
        return {old: p.name for p in self.params for old in p.deprecated_names}

    def current_names(self, values):
        """``values`` (a mapping of parameters) with deprecated names replaced by the current
        ones (a value given under both: the current name's)."""
        renamed = self.renamed()
        out = {renamed[k]: v for k, v in values.items() if k in renamed}
        out.update({k: v for k, v in values.items() if k not in renamed})
        return out


#: Parameters rclpy (Jazzy) declares on every node itself (see ship_sim.ros.params.check_overrides).
RCLPY_PARAMETERS = ('use_sim_time', 'start_type_description_service')


def readers_param(topic):
    """The string-array parameter ``<topic>_readers`` of a publisher that holds its first
    messages (ship_sim.ros.held_start) until the named nodes read them."""
    return Param(f'{topic}_readers', 'str[]', [''], f'lockstep: full names of the nodes that take '
                 f'{topic} by sequence (the launcher gives them from the graph); its first '
                 "messages are held until each is listed and matched ('' = none)", read_only=True)


def node_schema(package, executable):
    """The NodeSchema of ``executable`` in ``package`` (KeyError naming it if there is none)."""
    try:
        module = importlib.import_module(f'{package}.schema')
    except ModuleNotFoundError:
        raise KeyError(f'{package} has no parameter schema') from None
    schemas = getattr(module, 'SCHEMAS', {})
    if executable not in schemas:
        raise KeyError(f'{executable}: no parameter schema in package {package}')
    return schemas[executable]


def all_schemas():
    """Every node's NodeSchema, by package then node, in the order of the packages' SCHEMAS."""
    for package in ('ship_sim', 'ship_guidance', 'ship_autopilot', 'ship_planner'):
        yield from importlib.import_module(f'{package}.schema').SCHEMAS.values()


def allowed_text(kind, lo, hi, choices):
    if choices is not None:
        return 'one of ' + ', '.join(repr(c) for c in choices)
    what = {float: 'a number', int: 'an integer', bool: 'true or false', str: 'a string'}.get(
        kind, kind.__name__)
    if lo is not None and hi is not None:
        return f'{what} in [{lo}, {hi}]'
    if lo is not None:
        return f'{what} >= {lo}'
    if hi is not None:
        return f'{what} <= {hi}'
    return what


def one_line(text):
    return ' '.join(str(text).split())


def refusal(name, value, allowed):
    """The one-line refusal of a value (ship_sim.ros.params.ParameterError's text)."""
    return one_line(f'parameter {name!r} = {value!r} is not allowed: {allowed}')


def problem(kind, value, *, lo=None, hi=None, choices=None, check=None, allowed=None,
            allow_nonfinite=False):
    """None if a scalar ``value`` is allowed, else the text saying what would be (NodeParameters'
    test of start values and changes). ``kind``: the parameter's Python type."""
    if allowed is None:
        allowed = allowed_text(kind, lo, hi, choices)
    if kind is float and isinstance(value, int) and not isinstance(value, bool):
        value = float(value)
    if kind is bool:
        ok_type = isinstance(value, bool)
    elif kind is int:
        ok_type = isinstance(value, int) and not isinstance(value, bool)
    else:
        ok_type = isinstance(value, kind)
    if not ok_type:
        return allowed
    if kind is float and not allow_nonfinite and not math.isfinite(value):
        return allowed + ' (finite)'
    if choices is not None and value not in choices:
        return allowed
    if lo is not None and value < lo:
        return allowed
    if hi is not None and value > hi:
        return allowed
    if check is not None:
        extra = check(value)
        if extra:
            return extra
    return None


def check_param(schema, name, value, checks=None):
    """None if ``value`` is a valid start value of ``schema``'s parameter ``name``, else the
    one-line refusal the node would give, checked without ROS: type (a float parameter
    refuses an integer, as rclpy's static types do), range, choices and the schema's named
    check when it is a pure one (in ``schema.checks`` or ``checks``)."""
    p = schema[name]
    if p.is_list:
        ok = isinstance(value, list) and all(
            isinstance(x, p.kind) and not isinstance(x, bool) or (
                p.kind is float and isinstance(x, int) and not isinstance(x, bool))
            for x in value)
        if p.default and not value:
            ok = False
        if ok or (p.default == [] and isinstance(value, list)):
            return None
        what = 'numbers' if p.kind is float else 'strings'
        return refusal(name, value, f'a {"non-empty " if p.default else ""}list of {what}')
    if p.kind is float and isinstance(value, int) and not isinstance(value, bool):
        return refusal(name, value, "the node's parameter is a float, write "
                       f'{float(value)!r} (ROS parameter types are static)')
    check = None
    if p.check is not None:
        check = {**schema.checks, **(checks or {})}.get(p.check)
    bad = problem(p.kind, value, lo=p.lo, hi=p.hi, choices=p.choices, check=check,
                  allowed=p.allowed_text(), allow_nonfinite=p.allow_nonfinite)
    return None if bad is None else refusal(name, value, bad)
