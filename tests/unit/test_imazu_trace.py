"""The decision traces of scripts/imazu (trace_sbmpc.py, trace_vo.py) and the other files there
that users run.

- trace_sbmpc: at every traced decision that scored scenarios, the scenario the decision took
  is the cheapest listed (the stand-on hold, which keeps a scenario, is marked held), and each
  listed cost is the sum of its printed parts (SBMPC.cost_terms); SBMPC.costs is that sum.
- The entry files of the traces and the export (scripts/X.py, the code in scripts/imazu) run
  as their usage lines say.
"""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from imazu import trace_sbmpc

SCRIPTS = Path(__file__).resolve().parents[2] / 'scripts'


def _blocks(lines):
    """[(header, [row, ...])] of the decisions a trace printed."""
    blocks = []
    for line in lines:
        if line.startswith('t='):
            blocks.append((line, []))
        elif blocks and line.startswith(' ') and not line.lstrip().startswith('offset'):
            blocks[-1][1].append(line)
    return blocks


def test_trace_sbmpc_marks_the_cheapest_scenario_and_its_parts_add_up():
    lines = []
    # DNV situation 16: a stand-on crossing with a ship overtaking, acting from 467 s
    trace_sbmpc.trace('dnv', 16, 'mariner', every=40, top=4, limit_s=900.0, out=lines.append)
    blocks = _blocks(lines)
    acting = [(h, rows) for h, rows in blocks if ' avoid ' in h]
    assert len(acting) >= 3, 'acting from 467 s'
    for header, rows in acting:
        assert rows[0].startswith(' <'), (header, rows[0])
    for header, rows in blocks:
        assert len(rows) == 4
        for row in rows:
            cells = row[2:].split()
            cost, parts = float(cells[2]), [float(c) for c in cells[3:7]]
            assert cost == pytest.approx(sum(parts), abs=2e-3), row
    assert any(float(r[2:].split()[3]) > 0.0 for _, rows in acting for r in rows), \
        'a collision risk in the traced costs'
    assert lines[-1].startswith('ts2: closest')


def test_sbmpc_costs_are_the_sum_of_their_terms():
    from ship_guidance.colav import ShipState, Target
    from ship_guidance.sbmpc import SBMPC
    col = SBMPC()
    own = ShipState(north=0.0, east=0.0, course=0.0, speed=7.0)
    targets = (Target(north=3000.0, east=100.0, course=np.pi, speed=7.0, name='a'),
               Target(north=1500.0, east=-1500.0, course=np.pi / 2, speed=6.0, name='b'))
    sc = col.scenarios(own, targets, 0.0, 1.0)
    terms = col.cost_terms(sc)
    total = (terms['risk'] + terms['grounding'] + terms['port_turn'] + terms['not_apparent']
             + terms['deviation'])
    np.testing.assert_array_equal(col.costs(sc), total)
    np.testing.assert_array_equal(terms['risk'], terms['per_target'].max(axis=1))
    assert terms['per_target'].shape == (len(sc.offsets), 2) and total.min() >= 0.0


@pytest.mark.parametrize('name', ['trace_sbmpc.py', 'trace_vo.py', 'export_maritime_schema.py'])
def test_the_files_users_run_run_as_files(name):
    done = subprocess.run([sys.executable, str(SCRIPTS / name), '--help'],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-1000:]
    assert done.stdout.startswith('usage:')



def test_trace_vo_traces_a_scenario_file_as_its_case(tmp_path):
    """``--scenario`` (a failure the search wrote) traces the same run as the Imazu case it was
    written from."""
    from imazu import trace_vo
    from imazu.cases import load_cases
    from imazu.runner import case_scenario, write_scenario
    doc, route = case_scenario(1, load_cases()[1], 'mariner', 'vo', 700.0)
    path = write_scenario(doc, route, tmp_path)
    from_file, from_case = [], []
    trace_vo.trace(None, None, every=20, out=from_file.append, scenario=path)
    original = trace_vo.case_scenario
    trace_vo.case_scenario = lambda *a: (doc, route)      # the case at the same 700 s
    try:
        trace_vo.trace(1, 'mariner', every=20, out=from_case.append)
    finally:
        trace_vo.case_scenario = original
    assert from_file == from_case
    assert any(' avoid ' in line for line in from_file)
    assert from_file[-1].startswith('ts1: closest')
