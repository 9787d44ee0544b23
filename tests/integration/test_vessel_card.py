"""Adding a vessel model is its module plus one registration (issue 26 item 2).

A toy model (toy_vessel.py, kept outside ship_sim) is copied into a temporary folder and made
known in one place: ``register_card`` in this process, ``SHIPNAV_EXTRA_CARDS=toy_vessel`` for
the processes (identify_nomoto, the launcher and its nodes). It then goes through the
identification and gain design, the scenario check and a short lockstep run of the node graph.
"""
import importlib
import json
import math
import os
import shutil
import subprocess
import sys

import pytest

from ship_autopilot.gains import autopilot_gains, heading_loop_design, nomoto_gains
from ship_sim import models
from ship_mission.launcher import check_scenario
from ship_mission.scenario import ScenarioError, load_scenario

from harness import REPO_ROOT

HERE = REPO_ROOT / 'tests' / 'integration'
ROUTE = REPO_ROOT / 'scenarios' / 'routes' / 'flagship_mariner.yaml'
START_CROSS_M = 100.0


def _scenario(folder, model='toy'):
    path = folder / f'{model}.yaml'
    path.write_text(f"""name: {model}
duration_s: 60.0
stepping: lockstep
dt_s: 0.1
settle_s: 0.0
vessels:
  vessel_0:
    model: {model}
    route: {ROUTE}
    start: {{along_m: 0.0, cross_m: {START_CROSS_M}, heading_deg: 0.0}}
    guidance: {{law: los, lookahead_m: 300.0}}
    autopilot: {{controller: pd}}
""")
    return path


@pytest.fixture
def toy(tmp_path, monkeypatch):
    """The toy module imported from tmp_path, its card registered (and removed after), its
    gain tables identified into tmp_path by identify_nomoto in a process of its own."""
    shutil.copy(HERE / 'toy_vessel.py', tmp_path / 'toy_vessel.py')
    env = {**os.environ, models.EXTRA_CARDS_ENV: 'toy_vessel',
           'PYTHONPATH': f"{tmp_path}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"}
    done = subprocess.run([sys.executable, str(REPO_ROOT / 'scripts' / 'identify_nomoto.py'),
                           '--models', 'toy', '--out-dir', str(tmp_path)],
                          env=env, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stdout + done.stderr
    monkeypatch.syspath_prepend(str(tmp_path))
    module = importlib.import_module('toy_vessel')
    models.register_card(module.CARD)
    try:
        yield module, env
    finally:
        models.unregister_card('toy')
        sys.modules.pop('toy_vessel', None)


def test_unknown_model_is_refused_until_registered(tmp_path):
    with pytest.raises(ScenarioError, match="unknown model 'toy'"):
        check_scenario(load_scenario(_scenario(tmp_path)))
    with pytest.raises(ValueError, match="unknown model 'toy'"):
        models.card('toy')


def test_toy_card_through_gains_scenario_check_and_node_graph(toy, tmp_path, ros_graph, launch):
    module, env = toy
    model = models.make_model('toy')
    assert models.card('toy').gain_tables == str(tmp_path)

    # Identification: the toy is the fit's own first-order form, so the fit returns its K, T.
    nm = nomoto_gains('toy')
    assert nm['K'] == pytest.approx(model.K, rel=1e-3)
    assert nm['T'] == pytest.approx(model.T, rel=1e-3)
    # Gain design (ship_autopilot.gains docstring, Angelopoulos 2011 eq. 20 with a = -1/T,
    # b = -K/T): k1 = wn^2 T / K, k2 = (2 zeta wn T - 1) / K, wn = omega_n' U / L.
    design = heading_loop_design('toy')
    wn = models.card('toy').omega_n_nd * model.U / model.length
    assert design.omega_n == pytest.approx(wn, rel=1e-6)
    assert design.gains['pd']['k1'] == pytest.approx(wn ** 2 * nm['T'] / nm['K'], rel=1e-5)
    assert design.gains['pd']['k2'] == pytest.approx(
        (2 * design.zeta * wn * nm['T'] - 1) / nm['K'], rel=1e-5)
    assert autopilot_gains('toy') == design.gains

    # Scenario check in this process: the registered card is a known model.
    scenario_path = _scenario(tmp_path)
    check_scenario(load_scenario(scenario_path))

    # The node graph: every process of the run knows the toy through SHIPNAV_EXTRA_CARDS.
    ros_graph.env[models.EXTRA_CARDS_ENV] = env[models.EXTRA_CARDS_ENV]
    ros_graph.env['PYTHONPATH'] = f"{tmp_path}{os.pathsep}{ros_graph.env.get('PYTHONPATH', '')}"
    run = launch(scenario_path)
    assert run.wait(40.0) == 0, run.report()
    logs = run.run_dir() / 'logs'
    vessel_log = (logs / 'vessel_0.vessel_node.log').read_text()
    assert f'toy ({module.Toy.source})' in vessel_log
    assert f'U {model.U:.3f} m/s' in vessel_log
    autopilot_log = next(logs.glob('vessel_0.autopilot*.log')).read_text()
    assert 'pd autopilot for toy' in autopilot_log
    metrics = json.loads((run.run_dir() / 'metrics.json').read_text())['vessels']['/vessel_0']
    # It steers back towards the route: started 100 m off, a rudder of the wrong sign (or no
    # steering) would keep the cross-track error at or beyond the start offset.
    assert metrics['xte_rms_m'] < START_CROSS_M
    assert math.isfinite(metrics['xte_max_abs_m'])
