"""Parameter schemas of the ship_planner nodes (ship_sim.param_schema): route_node, planner_node.

Pure: the nodes declare from these tables, scripts/gen_param_files.py writes config/*.yaml from
them and the launcher checks scenario values against them before anything starts.
"""
import math

from ship_planner.chart import DEFAULT_MAX_CELLS, PROVIDERS
from ship_planner.optimal_route import DEFAULT_ENERGY_WEIGHT, PlannerConfig
from ship_sim.param_schema import NodeSchema, Param

NAN = float('nan')
POINTS_FRAMES = ('wgs84', 'enu')
BOX_KEYS = ('box_lat_min_deg', 'box_lat_max_deg', 'box_lon_min_deg', 'box_lon_max_deg')
#: route_node's route file when none is given (in the package's config/routes)
DEFAULT_ROUTE = 'example_enu.yaml'


def optional_range(lo, hi, what):
    """check for a float parameter where nan means 'not given', else lo <= value <= hi."""
    def check(value):
        if math.isnan(value) or lo <= value <= hi:
            return None
        return f'{what} in [{lo:g}, {hi:g}], or nan for not given'
    return check


ROUTE_NODE = NodeSchema('ship_planner', 'route_node', summary='a route file as a nav_msgs/Path',
                        params=(
    Param.of('length_unit_m', 0.0, 'metres per unit of a .wpt table (0: its own unit)', lo=0.0, hi=1e5, unit='m'),
    Param.of('max_arc_step_m', 25.0, 'longest sub-arc between Path poses', lo=0.1, hi=1e4, unit='m'),
    Param.of('route_file', DEFAULT_ROUTE, 'route file (.yaml or .wpt)', check='route_file',
        allowed='a readable, valid route file'),
    Param.of('watch_period_s', 1.0, 'file change check period (0: off)', lo=0.0, hi=3600.0, unit='s', read_only=True),
))
# route_file's 'route_file' check loads the file the way the node finds it: route_node gives it.

PLANNER_NODE = NodeSchema('ship_planner', 'planner_node', summary='an optimal route through a '
                          'chart, planned once', checks={
                              'latitude_or_nan': optional_range(-80.0, 80.0, 'degrees'),
                              'longitude_or_nan': optional_range(-180.0, 180.0, 'degrees'),
                              'metres_or_nan': optional_range(-1e6, 1e6, 'metres')},
                          # the example the config file carries: a passage off Busan
                          config_values={'box_lat_min_deg': 34.6, 'box_lat_max_deg': 35.12,
                                         'box_lon_min_deg': 128.36, 'box_lon_max_deg': 129.1,
                                         'start_lat_deg': 35.05, 'start_lon_deg': 129.05,
                                         'goal_lat_deg': 34.8, 'goal_lon_deg': 128.455,
                                         'turning_diameter_m': 1029.0,
                                         'route_name': 'busan_passage'}, params=(
    Param.of('chart_file', '', "chart file: S-57 ENC cell (.000) or an image (dark land); "
        "'' for the shoreline of the box", read_only=True),
    Param.of('shoreline', 'gshhg', 'shoreline data for the box', choices=PROVIDERS, read_only=True),
    *(Param.of(key, NAN, f'chart box {key[4:-4].replace("_", " ")} (nan: not given)', unit='deg',
               check=check, allow_nonfinite=True, read_only=True)
      for key, check in zip(BOX_KEYS, ('latitude_or_nan', 'latitude_or_nan', 'longitude_or_nan',
                                        'longitude_or_nan'))),
    Param.of('origin_lat_deg', NAN, "latitude of the 'map' origin (nan: box centre)", unit='deg',
        check='latitude_or_nan', allow_nonfinite=True, read_only=True),
    Param.of('origin_lon_deg', NAN, "longitude of the 'map' origin (nan: box centre)", unit='deg',
        check='longitude_or_nan', allow_nonfinite=True, read_only=True),
    Param.of('points_frame', 'wgs84', 'how start and goal are given: wgs84 (lat/lon deg) or '
        "enu (metres east/north of the origin)", choices=POINTS_FRAMES, read_only=True),
    *(Param.of(f'{end}_{axis}', NAN, f'{end} {what}', unit=unit, check=check,
               allow_nonfinite=True, read_only=True)
      for end in ('start', 'goal')
      for axis, what, unit, check in (
          ('lat_deg', 'latitude (points_frame wgs84)', 'deg', 'latitude_or_nan'),
          ('lon_deg', 'longitude (points_frame wgs84)', 'deg', 'longitude_or_nan'),
          ('x_m', 'east of the origin (points_frame enu)', 'm', 'metres_or_nan'),
          ('y_m', 'north of the origin (points_frame enu)', 'm', 'metres_or_nan'))),
    Param.of('resolution_m', 75.0, 'chart cell size', lo=1.0, hi=1e4, unit='m', read_only=True),
    Param.of('max_cells', DEFAULT_MAX_CELLS, 'largest raster allowed (cells)', lo=4, hi=10**9, read_only=True),
    Param.of('draft_m', 0.0, 'ship draft: ENC depth areas shallower are blocked (0: ignore depths)', lo=0.0, hi=100.0,
        unit='m', read_only=True),
    Param.of('cache_dir', '', "shoreline raster cache folder ('': $SHIPNAV_CACHE or "
        '~/.cache/shipnav)', read_only=True),
    Param.of('use_cache', True, 'reuse a cached shoreline raster', read_only=True),
    Param.of('clearance_m', 200.0, 'distance kept from land', lo=0.0, hi=1e5, unit='m', read_only=True),
    Param.of('turning_diameter_m', 0.0, 'vessel turning diameter: fillet radius = D '
        '(0: no fillets unless fillet_radius_m)', lo=0.0, hi=1e5, unit='m', read_only=True),
    Param.of('fillet_radius_m', 0.0, 'fillet radius, used instead of turning_diameter_m '
        'when > 0', lo=0.0, hi=1e5, unit='m', read_only=True),
    Param.of('min_fillet_radius_m', 0.0, 'smallest radius a tight corner may fall back to '
        '(0: half the fillet radius)', lo=0.0, hi=1e5, unit='m', read_only=True),
    Param.of('energy_weight', DEFAULT_ENERGY_WEIGHT, 'metres of sailing worth one radian of '
        'course change', lo=0.0, hi=1e6, unit='m/rad', read_only=True),
    Param.of('candidates', 3, 'distinct centre-line routes to optimise', lo=1, hi=20, read_only=True),
    Param.of('max_lines', PlannerConfig.max_lines, 'crossing lines (GA genes) per candidate', lo=1, hi=200,
        read_only=True),
    Param.of('population', PlannerConfig.population, 'GA population', lo=4, hi=10000, read_only=True),
    Param.of('generations', PlannerConfig.generations, 'GA generations (at most)', lo=1, hi=100000, read_only=True),
    Param.of('seed', 1, 'GA random seed', lo=0, hi=2**31 - 1, read_only=True),
    Param.of('refine', True, "local pattern search on the GA's best", read_only=True),
    Param.of('route_file_out', '', "route YAML file to write ('': none)", read_only=True),
    Param.of('route_name', 'planned_route', 'route name (in the log and the route file)', read_only=True),
    Param.of('max_arc_step_m', 25.0, 'longest sub-arc between Path poses', lo=0.1, hi=1e4, unit='m', read_only=True),
))

SCHEMAS = {s.node: s for s in (ROUTE_NODE, PLANNER_NODE)}
