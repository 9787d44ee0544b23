"""The chart-planned route (scripts/plan_route.py --results) and its run in the closed loop
(scripts/mission_results.py): doc/results/chart_planning.md."""
from results_pages.missions import _run
from results_pages.registry import table
from results_pages.tables import markdown_table


@table('chart_planning', 'route')
def route(data):
    """The planned route against the exact shortest path at the same clearance."""
    rows = [
        {'what': 'length (km)', 'planned': f"{data['route_length_m'] / 1e3:.2f}",
         'shortest': f"{data['shortest_path_length_m'] / 1e3:.2f}"},
        {'what': 'total course change (deg)', 'planned': f"{data['heading_change_deg']:.0f}",
         'shortest': f"{data['shortest_heading_change_deg']:.0f}"},
    ]
    table_md = markdown_table([('', 'what', ''), ('GA route with fillets', 'planned', ''),
                               ('exact shortest path', 'shortest', '')], rows)
    return (f"{data['chart']}; clearance {data['clearance_m']:g} m, fillet radius "
            f"{data['fillet_radius_m']:g} m:\n\n{table_md}\n"
            f"Length ratio {data['length_ratio']:.3f}; {data['waypoints']} waypoints; planning "
            f"{data['planning_time_s']:.1f} s, the chart {data['chart_time_s']:.1f} s (both under "
            "the load given below).\n")


@table('chart_planning', 'sailed')
def sailed(data):
    """The planned route sailed by the Mariner in the node graph."""
    metrics = _run(data, 'busan_passage_mariner')
    rows = [{'vessel': ns.strip('/'), **v} for ns, v in metrics['vessels'].items()]
    return markdown_table([
        ('vessel', 'vessel', ''), ('route (km)', lambda r: r['route_length_m'] / 1e3, '.2f'),
        ('sailed (km)', lambda r: r['distance_travelled_m'] / 1e3, '.2f'),
        ('completed', lambda r: 'yes' if r['finished'] else 'no', ''),
        ('time (s)', 'time_to_complete_s', '.0f'),
        ('XTE RMS after settling (m)', 'xte_rms_m', '.1f'),
        ('XTE max after settling (m)', 'xte_max_abs_m', '.1f'),
    ], rows)
