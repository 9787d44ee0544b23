"""Monte Carlo sweeps of the closed loop (``scripts/sweep.py``): issue 16 items 2-4.

A sweep file (``spec``) names a base environment and the parameters to vary, as a grid and
as seeded random draws; ``spec.expand`` turns it into episodes, each with its own parameters;
``episodes.run_chunk`` runs a chunk of episodes in one process (the batched closed loop, each
episode equal to the single-vessel in-process loop of scripts/evaluate_controllers.py;
``encounters``: an Imazu case with perturbed targets and collision avoidance, for a file naming
``encounter``);
``backends`` runs the chunks in local processes or as Ray tasks and streams the rows back;
``results`` writes the table (CSV) and the summary with confidence intervals; ``plots`` draws
them. The table depends only on the sweep file and its seed: never on the backend, the number
of workers or the chunking.
"""
