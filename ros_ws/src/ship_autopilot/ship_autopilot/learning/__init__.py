"""Learned steering (Martinsen and Lekkas 2018): the training environment (env, needs
gymnasium), its reward (reward) and numpy-only policy inference (policy). The eq. 9 state
the policy sees is ship_guidance.path_state.

Import the submodules directly; this package imports nothing so that the nodes, which need
only ``policy``, do not pull in gymnasium.
"""
