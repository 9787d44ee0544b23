"""Mission tooling shared by the launcher and the analysis scripts (``from mission import ...``).

- ``scenario``: scenario files (load_scenario); ``platoon``: the `platoon:` section and its
  checks; ``vessel_spec`` and ``fields``: the vessel mapping and the checked YAML fields both
  share (scenario -> platoon -> vessel_spec -> fields: no import cycle).
- ``launcher``: check and run a scenario; ``domain``: the ROS_DOMAIN_ID lease every graph on
  this machine takes (launcher, integration tests, seed batch, benchmarks).
- ``processes``: start/stop node processes from the colcon install.
- ``recorder``: rosbag2 (MCAP) recording of a running graph (rclpy + rosbags).
- ``bag``: read a bag back into numpy arrays per vessel namespace.
- ``metrics``: path-following metrics (pure numpy).
- ``plots``: PNG plots (matplotlib Agg).
- ``report``: bag -> metrics.json + plots (used by run_mission.py and replay_bag.py).

Submodules are imported on demand, so importing one does not pull in rclpy or matplotlib.
"""

import sys as _sys
from pathlib import Path as _Path

# The pure ship_* modules (e.g. the Odometry byte layout the bag reader shares with the nodes)
# from the source tree, appended: a sourced or use_install_tree() install still comes first.
for _pkg in ('ship_sim', 'ship_guidance', 'ship_autopilot', 'ship_planner'):
    _src = str(_Path(__file__).resolve().parents[2] / 'ros_ws' / 'src' / _pkg)
    if _src not in _sys.path:
        _sys.path.append(_src)
