"""Plant model registry of vessel cards: ``make_model('mariner')`` builds a model by its name.

Each model's module states its ``VesselCard`` (ship_sim.models.card) as ``CARD`` (or
``CARDS``); the registry holds one card per name, from three sources:

- the modules in ``_CARD_MODULES`` (the models shipped with ship_sim);
- the modules named in the environment variable ``SHIPNAV_EXTRA_CARDS`` (comma-separated
  importable module names, e.g. a model kept outside this package): read once, when this
  package is first imported, so every process of a run started with the variable set (the
  nodes included) knows the same models;
- ``register_card(card)`` at run time (in this process only; ``unregister_card`` removes it).

``MODEL_NAMES`` is the tuple of registered names (rebound by register_card, so read it as
``ship_sim.models.MODEL_NAMES`` or through ``model_names()`` where cards may be added later).
"""
import importlib
import os

from .base import ModelStateError, VesselModel
from .card import VesselCard

#: The modules whose CARD / CARDS are the shipped models, in registry order.
_CARD_MODULES = ('mariner', 'tanker', 'container', 'nomoto', 'nps_auv2')
#: Environment variable naming extra card modules (see the module docstring).
EXTRA_CARDS_ENV = 'SHIPNAV_EXTRA_CARDS'

__all__ = ['EXTRA_CARDS_ENV', 'MODEL_NAMES', 'ModelStateError', 'VesselCard', 'VesselModel',
           'card', 'cards', 'make_model', 'model_class', 'model_names', 'register_card',
           'unregister_card']

_CARDS = {}
MODEL_NAMES = ()


def _module_cards(module):
    found = getattr(module, 'CARDS', None) or (
        (module.CARD,) if hasattr(module, 'CARD') else ())
    if not found:
        raise ValueError(f'{module.__name__} defines no CARD or CARDS (ship_sim.models.card)')
    return found


def register_card(vessel_card):
    """Add a VesselCard to the registry; ValueError if its name is taken."""
    global MODEL_NAMES
    if not isinstance(vessel_card, VesselCard):
        raise ValueError(f'register_card takes a VesselCard, not {type(vessel_card).__name__}')
    if vessel_card.name in _CARDS:
        raise ValueError(f'model {vessel_card.name!r} is already registered')
    _CARDS[vessel_card.name] = vessel_card
    MODEL_NAMES = tuple(_CARDS)


def unregister_card(name):
    """Remove a card added by register_card (e.g. a test's); ValueError if not registered."""
    global MODEL_NAMES
    if _CARDS.pop(name, None) is None:
        raise ValueError(f'model {name!r} is not registered')
    MODEL_NAMES = tuple(_CARDS)


def _load_extra_cards(value):
    for module_name in filter(None, (m.strip() for m in value.split(','))):
        try:
            module = importlib.import_module(module_name)
        except ImportError as exc:
            raise ImportError(f'{EXTRA_CARDS_ENV}: cannot import {module_name!r}: {exc}') from None
        for c in _module_cards(module):
            register_card(c)


for _name in _CARD_MODULES:
    for _card in _module_cards(importlib.import_module(f'{__name__}.{_name}')):
        register_card(_card)
_load_extra_cards(os.environ.get(EXTRA_CARDS_ENV, ''))


def card(name):
    """The VesselCard registered under ``name``; ValueError naming the allowed names."""
    try:
        return _CARDS[name]
    except KeyError:
        raise ValueError(f"unknown model '{name}'; allowed: {', '.join(_CARDS)}") from None


def cards(kind=None):
    """The registered cards in registry order, only those labelled ``kind`` if given."""
    return tuple(c for c in _CARDS.values() if kind is None or kind in c.kinds)


def model_names(kind=None):
    """Registered model names, only those of cards labelled ``kind`` if given ('ship', 'mss',
    'nomoto'), or 'wind' / 'waves' for the models with wind loads / wave motion."""
    if kind == 'wind':
        return tuple(c.name for c in _CARDS.values() if c.has_wind)
    if kind == 'waves':
        return tuple(c.name for c in _CARDS.values() if c.has_waves)
    return tuple(c.name for c in cards(kind))


def model_class(name):
    """The model class registered under ``name``; ValueError naming the allowed names."""
    return card(name).model


def make_model(name, **params):
    """Build the model registered under ``name`` with keyword parameters (e.g. preset, U0, h)."""
    return card(name).make(**params)
