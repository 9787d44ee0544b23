"""The renderers of the results tables, by (study, table): studies register with ``@table``,
``render`` finds them (results_pages.studies imports every study so all are registered)."""

TABLES = {}


def table(study, name):
    """Decorator: register ``fn(data) -> Markdown`` as the table ``study.name``."""
    def register(fn):
        TABLES[(study, name)] = fn
        return fn
    return register


def render(study, name, data):
    try:
        fn = TABLES[(study, name)]
    except KeyError:
        known = ', '.join(f'{s}.{t}' for s, t in sorted(TABLES))
        raise KeyError(f"no table '{study}.{name}' (known: {known})") from None
    return fn(data)
