"""Physical bounds of what any input may say about a ship: beyond them a number is a fault.

MAX_COORDINATE_M (1e7 m, |north| and |east| from the map origin): the scale of the Earth (a
UTM-sized map); beyond it a number is not a place but a fault (e.g. 1e308, whose differences
overflow to inf and NaN). Routes, odometry, targets, light traffic and charts are held to it.

MAX_SPEED_MPS (50 m/s, about 97 kn): faster than any displacement or planing ship in traffic
(fast ferries and patrol craft make 40-60 kn, the fastest hydrofoils and wing-in-ground craft
about 90 kn); a target or light-traffic ship reported faster is a fault, not a ship. The same
figure is guidance_node's and follower_node's default ``max_plausible_speed``.
"""
MAX_COORDINATE_M = 1e7
MAX_SPEED_MPS = 50.0
