#!/usr/bin/env python3
"""Trace velocity-obstacle decisions in one Imazu run (in process, scripts/imazu/runner.py).

The code is imazu.trace_vo; its docstring has the usage.
"""
import sys

from imazu.trace_vo import main

if __name__ == '__main__':
    sys.exit(main())
