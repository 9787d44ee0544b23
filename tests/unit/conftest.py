"""Fixtures of the unit tests."""
import functools

import pytest


@functools.cache
def _domain_id():
    # One ROS_DOMAIN_ID of the shared lease scheme for this pytest process (held until it ends).
    from ship_mission.domain import LeaseError, lease_domain_id
    try:
        return lease_domain_id()
    except LeaseError as exc:
        pytest.fail(str(exc), pytrace=False)


@pytest.fixture
def make_node():
    """make(**parameter_overrides) -> (rclpy node, NodeParameters) in a private context."""
    import rclpy
    from rclpy.context import Context
    from rclpy.parameter import Parameter

    from ship_sim.ros.params import NodeParameters
    ctx = Context()
    rclpy.init(context=ctx, domain_id=_domain_id())
    nodes = []

    def make(**overrides):
        node = rclpy.create_node(f'params_test_{len(nodes)}', context=ctx,
                                 parameter_overrides=[Parameter(k, value=v)
                                                      for k, v in overrides.items()])
        nodes.append(node)
        return node, NodeParameters(node)

    yield make
    for node in nodes:
        node.destroy_node()
    ctx.try_shutdown()


@pytest.fixture
def scenario_variant(tmp_path):
    """variant(source, change) -> path of a copy of the scenario file ``source`` with
    ``change(data)`` applied; every relative route (and the `ais:` replay file) is made absolute
    against the source's folder (routes added by ``change`` too), so the copy reads the
    repository's files."""
    import yaml

    def variant(source, change):
        data = yaml.safe_load(source.read_text())
        change(data)
        for section in ('vessels', 'traffic'):
            entries = data.get(section)
            for entry in entries.values() if isinstance(entries, dict) else ():
                if isinstance(entry, dict) and isinstance(entry.get('route'), str):
                    entry['route'] = str((source.parent / entry['route']).resolve())
        ais = data.get('ais')
        if isinstance(ais, dict) and isinstance(ais.get('file'), str) and ais['file']:
            ais['file'] = str((source.parent / ais['file']).resolve())
        path = tmp_path / 'variant.yaml'
        path.write_text(yaml.safe_dump(data))
        return path
    return variant
