"""The Foxglove layout in the repo shows what the graph publishes (scripts/live_view_layout.json)."""
import json
import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
LAYOUT = REPO / 'scripts' / 'live_view_layout.json'
#: Per-vessel topics the nodes publish (doc/guide/topics.md): the layout may name only these.
PUBLISHED = {'odom', 'route', 'rudder', 'rudder_cmd', 'heading_cmd', 'cross_track_error',
             'heading', 'fix', 'nav_markers', 'colav_markers'}


def _panels(node):
    if isinstance(node, str):
        return [node]
    return _panels(node['first']) + _panels(node['second'])


def test_every_panel_of_the_layout_is_configured_and_the_issue_s_views_are_there():
    layout = json.loads(LAYOUT.read_text())
    panels = _panels(layout['layout'])
    assert sorted(panels) == sorted(layout['configById'])
    kinds = {p.split('!')[0] for p in panels}
    assert {'3D', 'map', 'Plot'} <= kinds
    plotted = {p['value'] for k, c in layout['configById'].items() if k.startswith('Plot!')
               for p in c['paths']}
    for needed in ('/vessel_0/cross_track_error.data', '/vessel_0/heading.data',
                   '/vessel_0/heading_cmd.data', '/vessel_0/rudder.data'):
        assert needed in plotted


def test_the_layout_names_only_topics_the_graph_publishes():
    text = LAYOUT.read_text()
    for topic in set(re.findall(r'"(/\w+/\w+)(?:\.\w+)?"', text)):
        assert topic.split('/')[2] in PUBLISHED, topic
