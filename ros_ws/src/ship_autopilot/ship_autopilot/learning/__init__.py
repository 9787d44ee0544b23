"""Learned steering (Martinsen and Lekkas 2018): eq. 9 state features, the training
environment (env, needs gymnasium) and numpy-only policy inference (policy).

Import the submodules directly; this package imports nothing so that the nodes, which need
only ``features`` and ``policy``, do not pull in gymnasium.
"""
