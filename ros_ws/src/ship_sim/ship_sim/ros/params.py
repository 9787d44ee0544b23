"""Declaring and validating ROS parameters, the same way in every node of the project.

Every node declares from its parameter schema (ship_sim.param_schema; the tables are in each
package's ``schema.py``)::

    self.params = NodeParameters(self, VESSEL_NODE)
    dt = self.params.param('dt')                     # default, range, description: the schema's
    self.params.param('speedup', on_change=self._set_speedup)
    values = self.params.declare_schema()            # or all of them, in the schema's order

``declare`` is the underlying call, for a parameter given by hand::

    dt = self.params.declare('dt', 0.1, 'integration step (s)', lo=1e-3, hi=1.0, read_only=True)
    mode = self.params.declare('stepping_mode', 'realtime', 'how the sim is paced',
                               choices=('realtime', 'lockstep'), read_only=True)
    self.params.declare('speedup', 1.0, 'realtime factor', lo=0.01, hi=1000.0,
                        on_change=self._set_speedup)

- Every parameter gets a default, a description and, where it applies, a range published in
  its ParameterDescriptor (floating_point_range / integer_range, so ``ros2 param describe``
  shows it) or a list of allowed strings (appended to the description).
- Start values (defaults, YAML, ``-p``) are checked when declared; an invalid one raises
  ParameterError, whose message is one line naming the parameter, the value and what is
  allowed. ship_sim.ros.run.run_node turns it into that line on stderr and exit code 2.
- Runtime changes go through the same checks in an on-set callback and are refused with the
  same message as the reason; read-only parameters cannot change at all. Accepted changes of a
  parameter with ``on_change`` are handed to it after they are stored.
- Types are static, as rclpy declares them from the default: ``-p dt:=1`` for a float parameter
  is refused (write ``1.0``) with rclpy's own message, wrapped the same way.
- A parameter given to the node (``-p``, ``--params-file``, also in ``/**:`` sections) that it
  does not declare is refused, not ignored: ``check_overrides`` (called by run_node once the
  node is built) raises ParameterError naming the key and the closest declared one.
"""
import difflib
import math

from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rcl_interfaces.msg import SetParametersResult
from rclpy.exceptions import InvalidParameterTypeException, InvalidParameterValueException

from ship_sim.param_schema import allowed_text as _allowed_text
from ship_sim.param_schema import one_line, problem


class ParameterError(Exception):
    """An invalid parameter value; str() is the one line to show the user."""

    def __init__(self, name, value=None, allowed=None, *, message=None):
        self.name = name
        self.value = value
        self.allowed = allowed
        if message is None:
            message = f'parameter {name!r} = {value!r} is not allowed: {allowed}'
        super().__init__(one_line(message))  # one line, whatever the source says


class _Spec:
    __slots__ = ('name', 'kind', 'lo', 'hi', 'choices', 'check', 'allowed', 'on_change',
                 'allow_nonfinite')

    def __init__(self, name, kind, lo, hi, choices, check, allowed, on_change, allow_nonfinite):
        self.name = name
        self.kind = kind
        self.lo = lo
        self.hi = hi
        self.choices = choices
        self.check = check
        self.allowed = allowed
        self.on_change = on_change
        self.allow_nonfinite = allow_nonfinite


class NodeParameters:
    """The declared parameters of one node, with their checks (see the module docstring)."""

    def __init__(self, node, schema=None):
        self._node = node
        self.schema = schema
        self._specs = {}
        node.add_on_set_parameters_callback(self._on_set)
        node.add_post_set_parameters_callback(self._post_set)
        self._declaring = False
        self._refused = None

    def declare(self, name, default, description, *, lo=None, hi=None, choices=None, check=None,
                allowed=None, unit='', read_only=False, on_change=None, allow_nonfinite=False):
        """Declare ``name`` with ``default``; return its (validated) start value.

        lo/hi: inclusive bounds for numbers; choices: allowed values (strings); check: a
        function value -> None if fine, else a short text of what is allowed (for conditions a
        range cannot express); allowed: overrides the text shown when a check fails.
        Raises ParameterError if the start value is invalid.
        """
        kind = type(default)
        if kind not in (bool, int, float, str):
            raise TypeError(f'parameter {name!r}: unsupported default type {kind.__name__}')
        if allowed is None:
            allowed = _allowed_text(kind, lo, hi, choices)
        desc = description + (f' [{unit}]' if unit else '')
        if choices is not None:
            desc += f"; allowed: {', '.join(str(c) for c in choices)}"
        descriptor = ParameterDescriptor(description=desc, read_only=read_only)
        if kind is float and (lo is not None or hi is not None):
            descriptor.floating_point_range = [FloatingPointRange(
                from_value=float(-math.inf if lo is None else lo),
                to_value=float(math.inf if hi is None else hi))]
        elif kind is int and (lo is not None or hi is not None):
            # IntegerRange is int64; a missing side becomes the int64 limit.
            descriptor.integer_range = [IntegerRange(
                from_value=int(-2**63 if lo is None else lo),
                to_value=int(2**63 - 1 if hi is None else hi))]
        self._specs[name] = _Spec(name, kind, lo, hi, choices, check, allowed, on_change,
                                  allow_nonfinite)
        self._declaring = True
        try:
            value = self._node.declare_parameter(name, default, descriptor).value
        except InvalidParameterTypeException as exc:
            raise ParameterError(name, message=f'parameter {name!r}: {exc.args[0]}') from None
        except InvalidParameterValueException as exc:
            # Refused by our on-set callback (which kept the value and the reason) or, before
            # it, by rclpy applying the descriptor's range (value only in the exception text).
            if self._refused is not None:
                value, bad = self._refused
                raise ParameterError(name, value, bad) from None
            raise ParameterError(name, _value_from(exc), allowed) from None
        finally:
            self._declaring = False
            self._refused = None
        return value

    def param(self, name, *, check=None, on_change=None):
        """Declare the schema's parameter ``name`` (ship_sim.param_schema.Param) and return its
        start value: the same as declare() with the schema's default, description, unit, range,
        choices and read_only. ``check``: the function of the Param's named check when the
        schema's ``checks`` cannot hold it (it needs the node); on_change as in declare().
        A value given under one of the Param's deprecated_names is used, with a warning."""
        p = self.schema[name]
        self._take_deprecated(p)
        if p.check is not None and check is None:
            check = self.schema.checks[p.check]   # KeyError: the node must give it
        if p.is_list:
            return self._declare_list(p)
        return self.declare(name, p.default, p.description, lo=p.lo, hi=p.hi,
                            choices=p.choices, check=check, allowed=p.allowed, unit=p.unit,
                            read_only=p.read_only, on_change=on_change,
                            allow_nonfinite=p.allow_nonfinite)

    def declare_schema(self, checks=None, on_change=None):
        """Declare every parameter of the schema, in its order; {name: start value}.
        checks / on_change: {name: function} for param()."""
        checks, on_change = checks or {}, on_change or {}
        return {p.name: self.param(p.name, check=checks.get(p.name),
                                   on_change=on_change.get(p.name))
                for p in self.schema.params}

    def _take_deprecated(self, p):
        overrides = self._node._parameter_overrides
        for old in p.deprecated_names:
            if old in overrides:
                self._node.get_logger().warning(
                    f'parameter {old!r} is deprecated and will be removed: use {p.name!r}')
                value = overrides.pop(old)
                overrides.setdefault(p.name, value)

    def _declare_list(self, p):
        """An array parameter (rclpy types it from the default; an empty default has no type,
        so it is declared dynamically typed and the node checks the elements)."""
        descriptor = ParameterDescriptor(description=p.description, read_only=p.read_only,
                                         dynamic_typing=not p.default)
        value = self._node.declare_parameter(p.name, list(p.default), descriptor).value
        return list(value) if p.default else value

    def value(self, name):
        """Current value of a declared parameter."""
        return self._node.get_parameter(name).value

    def reason(self, name, value):
        """None if ``value`` is allowed for ``name``, else the message of the refusal."""
        spec = self._specs[name]
        bad = self._problem(spec, value)
        if bad is None:
            return None
        return str(ParameterError(name, value, bad))

    # -- checks ------------------------------------------------------------------------------

    @staticmethod
    def _problem(spec, value):
        """None if fine, else the 'allowed' text explaining what would be."""
        return problem(spec.kind, value, lo=spec.lo, hi=spec.hi, choices=spec.choices,
                       check=spec.check, allowed=spec.allowed,
                       allow_nonfinite=spec.allow_nonfinite)

    def _on_set(self, parameters):
        for p in parameters:
            spec = self._specs.get(p.name)
            if spec is None:
                continue  # not ours (e.g. use_sim_time): leave it to whoever declared it
            bad = self._problem(spec, p.value)
            if bad is not None:
                if self._declaring:
                    self._refused = (p.value, bad)
                return SetParametersResult(successful=False,
                                           reason=str(ParameterError(p.name, p.value, bad)))
        return SetParametersResult(successful=True)

    def _post_set(self, parameters):
        if self._declaring:
            return  # start values are read by the node itself
        for p in parameters:
            spec = self._specs.get(p.name)
            if spec is not None and spec.on_change is not None:
                spec.on_change(p.value)


def check_overrides(node):
    """Raise ParameterError if ``node`` was given a parameter it does not declare.

    Compares the overrides rcl handed to the node (``-p``, ``--params-file`` entries matching
    it, ``/**:`` included) with its declared parameters, which include those rclpy declares
    itself (use_sim_time, start_type_description_service). Call once the node is built: every
    node declares all of its parameters in its constructor.
    """
    declared = set(node._parameters)
    unknown = sorted(set(node._parameter_overrides) - declared)
    if not unknown:
        return
    name = unknown[0]
    close = difflib.get_close_matches(name, sorted(declared), n=1)
    hint = f"; did you mean {close[0]!r}?" if close else ''
    more = f' ({len(unknown) - 1} more unknown: {", ".join(unknown[1:])})' if len(unknown) > 1 \
        else ''
    raise ParameterError(name, message=f'parameter {name!r} is not a parameter of '
                         f'{node.get_name()}{hint}{more}')


def _value_from(exc):
    """Best effort: the refused value from rclpy's InvalidParameterValueException text."""
    text = str(exc)
    start = text.find('(')
    end = text.find(')')
    value = text[start + 1:end] if 0 <= start < end else text
    for kind in (int, float):   # rclpy refuses only numbers by range: integers stay integers
        try:
            return kind(value)
        except ValueError:
            pass
    return value
