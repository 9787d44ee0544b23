"""Plant model registry: ``make_model('mariner')`` builds a model by its name.

Imports are lazy so a tool that needs one model does not import them all.
"""
import importlib

from .base import ModelStateError, VesselModel

_REGISTRY = {
    'mariner': ('ship_sim.models.mariner', 'Mariner'),
    'tanker': ('ship_sim.models.tanker', 'Tanker'),
    'container': ('ship_sim.models.container', 'Container'),
    'nomoto1': ('ship_sim.models.nomoto', 'Nomoto1'),
    'nomoto2': ('ship_sim.models.nomoto', 'Nomoto2'),
    'nps_auv2': ('ship_sim.models.nps_auv2', 'NpsAuv2'),
}

__all__ = ['MODEL_NAMES', 'ModelStateError', 'VesselModel', 'make_model', 'model_class']

MODEL_NAMES = tuple(_REGISTRY)


def model_class(name):
    """The model class registered under ``name``; ValueError naming the allowed names."""
    try:
        module, cls = _REGISTRY[name]
    except KeyError:
        raise ValueError(f"unknown model '{name}'; allowed: {', '.join(MODEL_NAMES)}") from None
    return getattr(importlib.import_module(module), cls)


def make_model(name, **params):
    """Build the model registered under ``name`` with keyword parameters (e.g. preset, U0, h)."""
    return model_class(name)(**params)
