"""A coast for the Imazu cases, and what the own ship's track did against it (pure).

The coast (``coast_chart``) runs parallel to the own ship's route, ``offset_m`` to its starboard
(east of the route on course 000), so the give-way alteration the rules ask for in a head-on
(Rule 14) or crossing give-way (Rule 15) encounter heads towards it. It is cut by a channel
running east-west across the meeting point's latitude, which the Imazu targets from starboard
come out of (case 2's crosser runs west along north 7408 m): targets hold course and speed and
see no land, and a coast they would start on would make no sense. The chart is a raster of the
land polygons (ship_planner.chart.polygon_chart), as SB-MPC sees land in the node graph.

``land_outcome`` reads a track against a chart: the smallest distance from the own ship's
position to land and whether it was ever on land (grounded). The distance is the chart's
distance from the nearest cell centre to the nearest land cell centre (Chart.distance_to_land),
so it is good to a cell diagonal.
"""
import numpy as np

#: The route's distance from the coast (m): 1 NM, inside which a give-way turn runs out of sea.
OFFSET_M = 1852.0
#: The channel through the coast (north m, from the own ship's start): 1 km either side of the
#: meeting point's latitude (every Imazu ship there after 20 min: 4 NM ahead).
CHANNEL_M = (6408.0, 8408.0)
#: The chart's extent (north min, north max, east min, east max, m): every run of the runner
#: (LIMIT_S at 12 kn, less than 25 km) stays inside it.
EXTENT_M = (-3000.0, 27000.0, -8000.0, 6000.0)
RESOLUTION_M = 20.0


def coast_polygons(offset_m=OFFSET_M, channel_m=CHANNEL_M, extent_m=EXTENT_M):
    """Land polygons (NED m): east of ``offset_m``, south and north of the channel, reaching a
    cell beyond the extent so the raster's edge is not a shore."""
    n0, n1, _, e1 = extent_m
    pad = 10.0 * RESOLUTION_M
    south, north = channel_m

    def box(a, b):
        return np.array([[a, offset_m], [a, e1 + pad], [b, e1 + pad], [b, offset_m]])
    return [box(n0 - pad, south), box(north, n1 + pad)]


def coast_chart(offset_m=OFFSET_M, channel_m=CHANNEL_M, extent_m=EXTENT_M,
                resolution_m=RESOLUTION_M):
    """The coast as a chart raster (ship_planner.chart.Chart) in the case's NED frame."""
    from ship_planner.chart import polygon_chart
    return polygon_chart(coast_polygons(offset_m, channel_m, extent_m), extent_m, resolution_m,
                         source=f'straight coast {offset_m:g} m to starboard of the route, channel '
                                f'north {channel_m[0]:g}..{channel_m[1]:g} m, '
                                f'{resolution_m:g} m cells')


def land_outcome(chart, t, own):
    """{'min_land_distance_m', 'grounded', 'time_on_land_s'} of the own ship's track (t (N,),
    own (N, >= 2) north, east) on ``chart``; a position off the chart is at sea."""
    points = np.asarray(own, dtype=float)[:, :2]
    land = chart.lookup(~chart.water, points)
    i, j, inside = chart.cell_index(points)
    dist = np.full(len(points), np.inf)
    dist[inside] = chart.distance_to_land()[i[inside], j[inside]]
    dt = np.diff(np.asarray(t, dtype=float), append=float(t[-1]))
    return {'min_land_distance_m': float(dist.min()), 'grounded': bool(land.any()),
            'time_on_land_s': float(dt[land].sum())}
