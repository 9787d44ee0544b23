"""A speed factor (colav_node's ``speed_factor_cmd``) acting on a ship's shaft.

Ships with a shaft (MSS tanker and container) run their shaft at ``factor x`` the shaft
command: propeller thrust and hull resistance both grow with the square of their speed in these
models (Fossen 2021, Ch. 6 and 9), so the steady speed through the water is about proportional
to the shaft speed and the factor scales the speed. Factor 0 means "stop the engine": the shaft
command goes to the model's lowest (the container's 1 rpm, its domain; the tanker's 0 rpm) and
the ship coasts down. A ship without a shaft input (the MSS Mariner: mariner.m takes the rudder
only, its speed is set by U0) cannot act on it.
"""
import math


def scaled_shaft(shaft_cmd, factor):
    """Shaft command (rpm) at ``factor`` of ``shaft_cmd``; factor 1 gives ``shaft_cmd`` itself
    (the same float); a negative factor counts as 0; None (no shaft) stays None."""
    if shaft_cmd is None or factor == 1.0:
        return shaft_cmd
    if not math.isfinite(factor):
        raise ValueError(f'speed factor must be finite, got {factor}')
    return shaft_cmd * max(factor, 0.0)
