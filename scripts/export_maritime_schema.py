#!/usr/bin/env python3
"""Write the 22 Imazu cases as maritime-schema TrafficSituation JSON files (one per case).

The code is imazu.export_maritime_schema; its docstring has the usage.
"""
import sys

from imazu.export_maritime_schema import main

if __name__ == '__main__':
    sys.exit(main())
