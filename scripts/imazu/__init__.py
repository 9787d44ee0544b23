"""The Imazu benchmark: cases, the in-process runner, scoring, figures (scripts/imazu_benchmark.py)."""
