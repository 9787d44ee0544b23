"""A search for collision-avoidance failures: encounters drawn from a parameter box, run in
process as the node graph runs them, scored by the evaluator; uniform Monte Carlo against the
cross-entropy method at an equal simulation budget (scripts/failure_search.py).

- ``encounter``: the parameterisation (target count, per target course, speed and CPA offset,
  the meeting time) and the geometry that turns a parameter vector into an encounter;
- ``sampling``: uniform sampling and the cross-entropy method over the unit box (pure numpy);
- ``episode``: one encounter run (scripts/imazu/runner.py) and scored
  (ship_guidance.colav_evaluation via imazu.evaluate), and its scenario YAML;
- ``distinct``: which failures count as distinct;
- ``study``: the search loop of one method, the results file;
- ``replay``: a written failure through run_mission's launcher, its minimum distance compared.
"""
