"""Heading autopilots (PD, fuzzy PID, learned policy) and the autopilot node."""
