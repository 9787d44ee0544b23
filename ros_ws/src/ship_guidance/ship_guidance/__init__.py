"""Guidance laws (LOS, integral LOS, circular arcs, curved paths, platoon pursuit) and the guidance node."""
