"""Scenarios and missions: run a scenario as a graph of node processes, record it, analyse it.

The launcher's command is ``ros2 run ship_mission run_mission`` (``cli``; scripts/run_mission.py
runs the same main); the analysis scripts use the modules (``from ship_mission import ...``).

- ``scenario``: scenario files (load_scenario); ``platoon``: the `platoon:` section and its
  checks; ``vessel_spec`` and ``fields``: the vessel mapping and the checked YAML fields both
  share (scenario -> platoon -> vessel_spec -> fields: no import cycle).
- ``launcher``: check and run a scenario; ``domain``: the ROS_DOMAIN_ID lease every graph on
  this machine takes (launcher, integration tests, seed batch, benchmarks).
- ``processes``: start/stop node processes from the colcon install.
- ``recorder``: rosbag2 (MCAP) recording of a running graph (rclpy + rosbags).
- ``bag``: read a bag back into numpy arrays per vessel namespace.
- ``bag_recovery``: rebuild a bag whose MCAP file lost its end (mcap reader); ``bag_check``:
  read a bag with two independent readers against its metadata.yaml; ``integrity``: is the
  record complete.
- ``metrics``: path-following metrics (pure numpy).
- ``plots``: PNG plots (matplotlib Agg).
- ``report``: bag -> metrics.json + plots + report.html (used by run_mission.py and replay_bag.py).
- ``html_report``: self-contained HTML pages (a run's report.html, batch pages);
  ``browser_check``: open a page in headless Chromium (scripts/check_report.py, its test).

Submodules are imported on demand, so importing one does not pull in rclpy or matplotlib.
Modules use each other's public names only (tests/unit/test_mission_private_names.py). The
ship_* packages come from the interpreter's path: the install tree where
`ros_ws/install/setup.bash` is sourced, the source folders under pytest (doc/guide/install.md).
"""
