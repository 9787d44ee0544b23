"""A scenario's `aivdm_out:` block: its vessels as NMEA AIS for chart plotters (aivdm_out_node).

    aivdm_out:
      udp: 127.0.0.1:10110          # host:port (OpenCPN: a UDP input on that port); '' none
      file: aivdm.nmea              # relative: in the run folder; '' none
      origin: {lat_deg: 63.44, lon_deg: 10.40}   # default: the ais: origin, else the first
                                    #   route's, else 0/0
      mmsi: {vessel_0: 257000100}   # per namespace; default 257999000 + its index (made up)
      static:                       # per namespace, all optional: class (A, B, SO), name,
        target_1: {class: B, name: Yacht, ship_type: 37, length_m: 12, beam_m: 4}
                                    #   callsign, ship_type, length_m, beam_m, antenna_x_m,
                                    #   antenna_y_m
      loss_probability: 0.05        # any other aivdm_out_node parameter (sensor model)

Every vessel, traffic vessel and light target is sent; the first vessel of `vessels:` is the
own ship (AIVDO), all others AIVDM. A full vessel's length and beam are its model's overall
length and beam where the model's card has them (ship_sim.models.card), else its
length between perpendiculars and no beam; its ship type 70 (cargo). A light target has no
dimensions unless `static` gives them.
"""
import json

from ship_mission.fields import ScenarioError
from ship_mission.node_checks import node_parameter_names
from ship_mission.scenario import scenario_origin
from ship_guidance.nav_display import DEFAULT_ORIGIN_DEG

KEYS = {'udp', 'file', 'origin', 'mmsi', 'static'}
STATIC_KEYS = {'class', 'name', 'callsign', 'ship_type', 'length_m', 'beam_m', 'antenna_x_m',
               'antenna_y_m'}
NODE = ('aivdm_out_node', 'ship_guidance')
MMSI_BASE = 257999000


def _fail(scenario, key, what):
    raise ScenarioError(f'{scenario.file}: aivdm_out.{key}: {what}')


def _model_dimensions(model):
    from ship_sim.models import card
    c = card(model)
    if c.Loa is not None and c.beam is not None:
        return c.Loa, c.beam
    return c.Lpp, 0.0


def aivdm_parameters(scenario, run):
    """aivdm_out_node's parameters for ``scenario`` (its `aivdm_out` mapping), the file in the
    run folder ``run`` when relative. ScenarioError names the key of anything wrong."""
    block = scenario.aivdm_out
    if not isinstance(block, dict):
        _fail(scenario, '', 'a mapping (udp, file, origin, mmsi, static, sensor parameters)')
    names = node_parameter_names(*reversed(NODE)) - {'vessels', 'origin_lat_deg',
                                                      'origin_lon_deg', 'use_sim_time'}
    for key in block:
        if key not in KEYS | names:
            _fail(scenario, key, f'unknown key; allowed: {", ".join(sorted(KEYS | names))}')
    namespaces = [s.namespace for s in scenario.vessels] + [t['name'] for t in scenario.light]
    mmsi = block.get('mmsi') or {}
    static = block.get('static') or {}
    for key, d in (('mmsi', mmsi), ('static', static)):
        if not isinstance(d, dict):
            _fail(scenario, key, 'a mapping namespace -> value')
        for ns in d:
            if ns not in namespaces:
                _fail(scenario, f'{key}.{ns}', f'no such vessel; one of {", ".join(namespaces)}')
    vessels = []
    for i, ns in enumerate(namespaces):
        spec = scenario.vessels[i] if i < len(scenario.vessels) else None
        v = {'topic': f'/{ns}/odom', 'mmsi': int(mmsi.get(ns, MMSI_BASE + i)),
             'own': i == 0 and spec is not None and not spec.traffic, 'name': ns.upper()}
        if spec is not None:
            length, beam = _model_dimensions(spec.model)
            v.update(ship_type=70, length_m=float(length), beam_m=float(beam))
        extra = static.get(ns) or {}
        if not isinstance(extra, dict) or set(extra) - STATIC_KEYS:
            _fail(scenario, f'static.{ns}', f'a mapping of {", ".join(sorted(STATIC_KEYS))}')
        v.update(extra)
        vessels.append(v)
    if len({v['mmsi'] for v in vessels}) < len(vessels):
        _fail(scenario, 'mmsi', 'every vessel needs its own MMSI')
    origin = block.get('origin')
    if origin is not None:
        if not isinstance(origin, dict) or set(origin) != {'lat_deg', 'lon_deg'}:
            _fail(scenario, 'origin', 'a mapping {lat_deg, lon_deg}')
        lat0, lon0 = float(origin['lat_deg']), float(origin['lon_deg'])
    else:   # the scenario's origin, as the display's fix uses it (one place picks it)
        lat0, lon0 = scenario_origin(scenario) or DEFAULT_ORIGIN_DEG
    file = str(block.get('file', '') or '')
    if file and not file.startswith('/'):
        file = str(run / file)
    # The sensor parameters are floats to the node (rclpy refuses an int for a float): 0 -> 0.0
    params = {k: v if k == 'seed' or not isinstance(v, int) or isinstance(v, bool) else float(v)
              for k, v in block.items() if k in names}
    params.update(use_sim_time=False, vessels=json.dumps(vessels), origin_lat_deg=lat0,
                  origin_lon_deg=lon0, file=file, udp=str(block.get('udp', '127.0.0.1:10110')))
    return params
