"""The vessel card registry (ship_sim.models, ship_sim.models.card)."""
import inspect
import os
import subprocess
import sys

import numpy as np
import pytest

from ship_sim import models
from ship_sim.environment.sea_state import MODEL_RAO, rao_table_for
from ship_sim.environment.wind import WIND_PROFILES, wind_profile
from ship_sim.models import VesselCard, card, cards, make_model, model_names


@pytest.mark.parametrize('name', models.MODEL_NAMES)
def test_node_kwargs_are_constructor_keywords(name):
    c = card(name)
    params = set()
    for cls in c.model.__mro__:    # **kw passes keywords on to a base class's __init__
        if '__init__' in vars(cls):
            sig = inspect.signature(cls.__init__).parameters
            params |= set(sig)
            if not any(p.kind is p.VAR_KEYWORD for p in sig.values()):
                break
    for keyword in c.node_kwargs.values():
        assert keyword in params, f'{name}: {keyword} is not a keyword of {c.model.__name__}'


@pytest.mark.parametrize('name', models.MODEL_NAMES)
def test_speed_is_the_hypot_of_surge_and_sway(name):
    m = make_model(name)
    x = np.stack([m.initial_state(), m.initial_state()])
    x[1, m.IV] = 0.5           # a sway velocity adds in quadrature
    u = np.asarray(m.surge_speed(x))
    assert np.allclose(m.speed(x), np.hypot(u, x[:, m.IV]))
    assert card(name).service_speed == pytest.approx(float(m.speed(m.initial_state())))


def test_kinds_select_the_cards():
    assert set(model_names('mss')) <= set(model_names('ship'))
    assert model_names('wind') == tuple(WIND_PROFILES)
    assert model_names('waves') == tuple(MODEL_RAO)
    for c in cards('mss'):
        assert c.has_wind and c.model.takes_external_loads
        assert wind_profile(c.name) is c.wind
        # The stated overall length is longer than between perpendiculars.
        assert c.Loa > c.Lpp
    assert 'nps_auv2' not in model_names('ship')


def test_rao_table_follows_the_card():
    for c in cards():
        if c.has_waves:
            table = rao_table_for(c.name, c.Lpp)
            if c.rao[1]:        # Froude-scaled to the model's length
                assert table.length == pytest.approx(c.Lpp)
        else:
            with pytest.raises(ValueError, match='no wave RAOs'):
                rao_table_for(c.name, c.Lpp)


def test_register_and_unregister():
    extra = VesselCard(name='mariner_copy', model=card('mariner').model, kinds={'mss'})
    models.register_card(extra)
    try:
        assert 'mariner_copy' in models.MODEL_NAMES
        assert 'mariner_copy' in model_names('mss')
        assert make_model('mariner_copy').name == 'mariner'
        with pytest.raises(ValueError, match='already registered'):
            models.register_card(extra)
    finally:
        models.unregister_card('mariner_copy')
    assert 'mariner_copy' not in models.MODEL_NAMES
    with pytest.raises(ValueError, match='not registered'):
        models.unregister_card('mariner_copy')
    with pytest.raises(ValueError, match='takes a VesselCard'):
        models.register_card(('toy', object))


def test_card_refuses_a_node_parameter_vessel_node_does_not_have():
    with pytest.raises(ValueError, match='not vessel_node parameters'):
        VesselCard(name='x', model=card('mariner').model, node_kwargs={'speed': 'U0'})


def test_extra_cards_module_that_does_not_import_is_named():
    env = {**os.environ, models.EXTRA_CARDS_ENV: 'no_such_card_module'}
    done = subprocess.run([sys.executable, '-c', 'import ship_sim.models'], env=env,
                          capture_output=True, text=True, timeout=60)
    assert done.returncode != 0
    assert "SHIPNAV_EXTRA_CARDS: cannot import 'no_such_card_module'" in done.stderr
