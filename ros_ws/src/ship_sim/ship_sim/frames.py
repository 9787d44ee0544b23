"""Frames and angles: the one place where NED/FRD (science) meets ENU/FLU (topics).

Pure modules follow Fossen: NED world (x north, y east), body FRD (u surge, v sway to
starboard, r yaw rate clockwise), heading psi clockwise from north. Topics follow REP-103/105:
ENU world, FLU body, yaw counter-clockwise from east. All functions accept numpy arrays.

    x_E = y_N,  y_E = x_N,  yaw_ENU = pi/2 - psi_NED,  v_FLU = -v_FRD,  r_FLU = -r_FRD

The rudder sign is frame independent: a positive rudder angle turns the vessel to port
(ENU yaw increases, NED psi decreases), for every model (see ship_sim.models.base).
"""
import numpy as np

TWO_PI = 2.0 * np.pi


def wrap_angle(a):
    """Wrap an angle (rad) to [-pi, pi). Works on floats (stays a float) and numpy arrays."""
    return (a + np.pi) % TWO_PI - np.pi


def psi_to_yaw(psi):
    """NED heading (clockwise from north) -> ENU yaw (counter-clockwise from east), wrapped."""
    return wrap_angle(np.pi / 2.0 - psi)


def yaw_to_psi(yaw):
    """ENU yaw -> NED heading, wrapped. The map is its own inverse."""
    return wrap_angle(np.pi / 2.0 - yaw)


def yaw_to_compass_deg(yaw):
    """ENU yaw (rad) -> compass heading (deg, clockwise from north, in [0, 360)): the 000-360
    a mariner reads, north 000, east 090, south 180, west 270."""
    deg = np.mod(np.degrees(np.pi / 2.0 - np.asarray(yaw, dtype=float)), 360.0)
    deg = np.where(deg >= 360.0, 0.0, deg)   # the mod of a tiny negative rounds up to 360.0
    return float(deg) if deg.ndim == 0 else deg


def ned_to_enu_xy(north, east):
    """NED position (north, east) -> ENU position (x east, y north)."""
    return east, north


def enu_to_ned_xy(x_east, y_north):
    """ENU position (x east, y north) -> NED position (north, east)."""
    return y_north, x_east


def frd_to_flu_twist(u, v, r):
    """Body velocities FRD (surge, sway starboard, yaw rate clockwise) -> FLU."""
    return u, -v, -r


def flu_to_frd_twist(u, v, r):
    """Body velocities FLU -> FRD (the map is its own inverse)."""
    return u, -v, -r
