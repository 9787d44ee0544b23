"""Defaults of the guidance nodes' parameters that the launcher needs too (pure, no rclpy).

guidance_node and follower_node declare these parameters with these values; the launcher's
platoon check (ros_ws/src/ship_mission/ship_mission/platoon.py) fills the keys a scenario leaves out from them; the
packages' config/*.yaml list the same values (tests/unit/test_platoon_config.py checks it).
"""

#: guidance_node: law, LOS look-ahead (m) and ILOS integral gain sigma (m/s).
GUIDANCE_DEFAULTS = {'law': 'ilos', 'lookahead_m': 500.0, 'integral_gain': 0.5}
#: follower_node: look-ahead floor and cap (m; cap 0 = none), fallback LOS look-ahead (m) and
#: the integral gain on its own cross-track error (m/s).
FOLLOWER_DEFAULTS = {'min_lookahead_m': 200.0, 'max_lookahead_m': 0.0, 'lookahead_m': 500.0,
                     'integral_gain': 0.0}
