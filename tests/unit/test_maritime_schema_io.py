"""The Imazu cases written as maritime-schema TrafficSituation JSON come back as the same
cases; trafficgen's schema-0.2.0 situation files are read by our own reader (they do not
validate in maritime-schema 0.0.7: integer ship ids where it requires UUIDs)."""
import json
import math
import uuid

import pytest

pytest.importorskip('maritime_schema', reason='maritime-schema not installed (make venv-interop)')

from imazu.cases import load_cases  # noqa: E402
from imazu.export_maritime_schema import same_case  # noqa: E402
from imazu.maritime_schema_io import (KNOT_MPS, dumps, from_traffic_situation, loads,  # noqa: E402
                                      to_traffic_situation)
from imazu.trafficgen_situations import read_situation  # noqa: E402
from ship_sim.geodetic import ned_to_geodetic  # noqa: E402


def test_every_imazu_case_round_trips_through_the_schema_json():
    cases = load_cases()
    for n, case in cases.items():
        text = dumps(to_traffic_situation(n, case))
        number, back = from_traffic_situation(loads(text))
        assert number == n
        assert same_case(back, case), n
        # the file names its fields as the schema does, so other readers find them
        data = json.loads(text)
        assert {'ownShip', 'targetShips', 'title'} <= set(data)
        assert len(data['targetShips']) == len(case['targets'])
        assert all(uuid.UUID(t['static']['id']) for t in data['targetShips'])


def test_writing_a_case_twice_gives_the_same_file():
    case = load_cases()[5]
    assert dumps(to_traffic_situation(5, case)) == dumps(to_traffic_situation(5, case))


def test_a_target_placed_by_hand_lands_where_the_case_puts_it():
    """A target 7408 m north, 7408 m east of the own ship at 12 kn on course 270: the file
    gives the tangent-plane position, the speed in knots and the course in degrees."""
    case = {'own': {'north_m': 0.0, 'east_m': 0.0, 'course_deg': 0.0, 'speed_mps': 6.1733},
            'targets': [{'name': 'ts1', 'north_m': 7408.0, 'east_m': 7408.0, 'course_deg': 270.0,
                         'speed_mps': 6.1733, 'colregs': 'crossing-give-way'}]}
    origin = (60.0, 5.0)
    data = json.loads(dumps(to_traffic_situation(2, case, origin)))
    t = data['targetShips'][0]['initial']
    lat, lon = ned_to_geodetic(7408.0, 7408.0, *origin)
    assert math.isclose(t['position']['latitude'], float(lat), abs_tol=1e-12)
    assert math.isclose(t['position']['longitude'], float(lon), abs_tol=1e-12)
    assert math.isclose(t['sog'], 6.1733 / KNOT_MPS) and t['cog'] == 270.0
    # a degree of latitude is about 111 km: the target is about 7408 / 111000 deg north
    assert math.isclose(t['position']['latitude'] - origin[0], 7408.0 / 111_400.0, rel_tol=0.01)


def _trafficgen_like(path, title, ships):
    """A file in trafficgen's schema-0.2.0 layout (written here, not taken from its data)."""
    def ship(i, lat0, lon0, lat1, lon1, sog):
        return {'initial': {'heading': 0.0}, 'static': {'id': i, 'dimensions': {'length': 100.0}},
                'waypoints': [{'position': {'lat': lat0, 'lon': lon0}, 'leg': {'sog': sog}},
                              {'position': {'lat': lat1, 'lon': lon1}, 'leg': {'sog': sog}}]}
    own, *targets = [ship(i + 1, *s) for i, s in enumerate(ships)]
    path.write_text(json.dumps({'schemaVersion': '0.2.0', 'title': title, 'ownShip': own,
                                'targetShips': targets}))


def test_trafficgen_head_on_file_reads_as_a_head_on_case(tmp_path):
    f = tmp_path / 'ho.json'
    # own ship northbound from (58.7, 10.5); target 0.1 deg (about 11.1 km) north, southbound
    _trafficgen_like(f, 'HO', [(58.7, 10.5, 58.8, 10.5, 10.0), (58.8, 10.5, 58.7, 10.5, 12.0)])
    title, case = read_situation(f)
    assert title == 'HO'
    own, (ts,) = case['own'], case['targets']
    assert own['north_m'] == 0.0 and own['east_m'] == 0.0
    assert math.isclose(own['course_deg'] % 360.0, 0.0, abs_tol=1e-6) or \
        math.isclose(own['course_deg'], 360.0, abs_tol=1e-6)
    assert math.isclose(ts['course_deg'], 180.0, abs_tol=1e-6)
    assert math.isclose(ts['north_m'], 11_130.0, rel_tol=0.01) and abs(ts['east_m']) < 1e-6
    assert math.isclose(ts['speed_mps'], 12.0 * KNOT_MPS) and ts['colregs'] == 'head-on'


def test_a_trafficgen_file_fails_the_pinned_schema_on_its_integer_ids(tmp_path):
    from pydantic import ValidationError
    f = tmp_path / 'ho.json'
    _trafficgen_like(f, 'HO', [(58.7, 10.5, 58.8, 10.5, 10.0), (58.8, 10.5, 58.7, 10.5, 12.0)])
    with pytest.raises(ValidationError) as err:
        loads(f.read_text())
    assert {e['type'] for e in err.value.errors()} == {'uuid_type'}
