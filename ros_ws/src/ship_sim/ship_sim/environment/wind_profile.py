"""The above-water geometry of a ship that its wind loads need (ship_sim.environment.wind).

A module of its own, free of imports, so a model's card (ship_sim.models.card) can state it.
"""
from dataclasses import dataclass


@dataclass(frozen=True)
class WindProfile:
    """Above-water geometry of a ship for the wind coefficients (m, m^2; doc/results/wind_waves.md)."""

    Loa: float      # length overall
    B: float        # beam
    ALw: float      # lateral projected area
    AFw: float      # frontal projected area
    A_SS: float     # lateral projected area of the superstructure (Isherwood)
    S: float        # perimeter of the lateral projection, without waterline and masts
    C: float        # distance from the bow to the centroid of ALw
    M: int          # number of distinct mast / king-post groups (Isherwood)
    sH: float       # height of the centroid of ALw above the waterline (Blendermann)
    sL: float       # longitudinal position of the centroid of ALw from midships, + forward
    blendermann_type: int   # 1..17, wind_coefficients.BLENDERMANN_TYPES
    source: str
