"""Moved to ship_sim.geodetic (where the frames live, so ship_guidance can use it too); this
name stays for existing callers."""
from ship_sim.geodetic import (WGS84_A, WGS84_B, WGS84_E2, WGS84_F, geodetic_to_ned,  # noqa: F401
                               ned_to_geodetic)
