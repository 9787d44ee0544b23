"""Results pages whose numbers are generated: a study's command writes a results file (JSON),
which is committed under ``doc/results/data/``; ``scripts/render_results.py`` turns it into the
tables of the study's page, between markers, and ``--check`` (a test) fails when a committed
page differs from what its committed results file renders. Numbers are typed by no one.
"""
