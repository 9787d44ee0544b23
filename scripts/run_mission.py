#!/usr/bin/env python3
"""Run a scenario: `scripts/run_mission.py scenarios/<name>.yaml [options]` (`--help` lists them).

The same program as `ros2 run ship_mission run_mission` (ship_mission.cli, where the options and
exit codes are documented): every node starts as its own process from the colcon install, a bag
is recorded, and metrics, plots and report.html go to runs/<name>-<time>/ (runs/latest points
there). Run it with the install sourced (`source ros_ws/install/setup.bash`; `make demo
SCENARIO=...` does that), or with PYTHONPATH naming the source folders (doc/guide/install.md).
"""
import sys

from ship_mission.cli import main

if __name__ == '__main__':
    sys.exit(main())
