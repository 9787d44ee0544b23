"""A chart (ship_planner.chart.Chart) as a nav_msgs/OccupancyGrid (the ROS map convention).

ENU 'map' frame, unrotated origin at the lower-left corner of cell [0, 0] (the chart's cell
centres sit at north0 + i res, east0 + j res, so the corner is half a cell south-west of it);
row i of the data runs along y (north), column j along x (east); 100 = land or too shallow,
0 = navigable water. colav_node reads it back (ship_guidance.land_mask.LandMask.from_occupancy)
for SB-MPC's grounding cost; RViz and Foxglove draw it as a map.
"""
import numpy as np
from nav_msgs.msg import OccupancyGrid

LAND, WATER = 100, 0


def chart_to_occupancy_grid(chart, stamp, frame_id='map'):
    msg = OccupancyGrid()
    msg.header.stamp, msg.header.frame_id = stamp, frame_id
    ny, nx = chart.water.shape
    res = chart.resolution_m
    msg.info.map_load_time = stamp
    msg.info.resolution = float(res)
    msg.info.width, msg.info.height = int(nx), int(ny)
    msg.info.origin.position.x = float(chart.east0 - 0.5 * res)
    msg.info.origin.position.y = float(chart.north0 - 0.5 * res)
    msg.info.origin.orientation.w = 1.0
    msg.data = np.where(chart.water, WATER, LAND).astype(np.int8).ravel().tolist()
    return msg
