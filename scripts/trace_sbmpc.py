#!/usr/bin/env python3
"""Trace SB-MPC's decisions in one Imazu or DNV run (in process, scripts/imazu/runner.py): why

The code is imazu.trace_sbmpc; its docstring has the usage.
"""
import sys

from imazu.trace_sbmpc import main

if __name__ == '__main__':
    sys.exit(main())
