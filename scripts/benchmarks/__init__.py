"""Benchmark sections of ``scripts/bench.py`` (``make bench``); a registry, one module each.

A section is a function ``run(quick: bool) -> dict`` returning a JSON-serialisable result:

    {'title': str,                       # one line, printed above the table
     'columns': [[key, header], ...],    # table columns, in order
     'rows': [{key: value, ...}, ...],   # one row per measurement (numbers or short text)
     'goals': [{'text': str, 'value': float, 'target': float, 'unit': str, 'met': bool}],
     'notes': [str, ...],                # caveats (e.g. a model without the float path)
     'failed': bool,                     # optional: part of it failed (numbers kept)
     ...}                                # any extra figures (kept in the JSON only)

``common.goal`` and ``common.format_section`` build and print these. A section that raises is
reported as failed and the others still run. To add a section, write a module with such a
function and add one line to ``SECTIONS`` below (name -> (module, function, description));
modules are imported only when their section runs, so e.g. rclpy is loaded only for the ROS
sections.
"""
import importlib

#: Section name -> (module in this package, function, one-line description). Order = run order.
SECTIONS = {
    'models': ('models', 'run', 'single-vessel derivative and RK4 step cost per model'),
    'batched': ('batched', 'run', 'batched RK4 throughput (vessel-steps/s) for the MSS ships'),
    'wind': ('wind', 'run', 'cost of the wind loads per simulator step, one vessel and batched'),
    'node_jitter': ('node_jitter', 'run', 'odom inter-arrival jitter of a realtime vessel_node'),
    'lockstep': ('lockstep', 'run', 'flagship graph in lockstep: real-time factor vs a bare '
                 'relay'),
    'composition': ('composition', 'run', 'several nodes per process vs one each: platoon of '
                    '1/3/5 Mariners in lockstep (wall, CPU per vessel), flagship vs relay floor'),
    'live_view': ('live_view', 'run', 'flagship lockstep run with and without --live (the '
                  'Foxglove live view), with and without a client'),
    'realtime_latency': ('realtime_latency', 'run', 'flagship graph in realtime: odom -> '
                         'rudder_cmd latency and missed steps'),
    'closed_loop_inprocess': ('closed_loop_inprocess', 'run',
                              'flagship loop with the pure modules in one process (no ROS)'),
    'batch_closed_loop': ('batch_closed_loop', 'run', 'batched closed loop (ILOS + PD, N '
                          'episodes as arrays) against one vessel and the plant alone'),
    'kernels': ('kernels', 'run', 'batched closed loop per MSS ship on numpy and on the '
                'compiled kernels (numba), with the plant alone on each'),
    'colav': ('colav', 'run', 'one collision-avoidance decision with 10 targets (SB-MPC, VO)'),
    'waves': ('waves', 'run', 'per-step cost of the wave-frequency motion and the wave filter'),
    'imazu': ('imazu', 'run', 'Imazu benchmark runs in process: time per run, decisions/s'),
    'sweep': ('sweep', 'run', 'scripts/sweep.py throughput: local processes and Ray, 1 and 2 '
              'workers'),
    'controllers': ('controllers', 'run', "Martinsen and Lekkas 2018's Table I: classical controllers vs the "
                    'learned policy on curved paths'),
}


def section_function(name):
    """The ``run(quick)`` function of a registered section (ValueError for an unknown name)."""
    try:
        module, func, _ = SECTIONS[name]
    except KeyError:
        raise ValueError(f"unknown section {name!r}; allowed: {', '.join(SECTIONS)}") from None
    return getattr(importlib.import_module(f'{__name__}.{module}'), func)
