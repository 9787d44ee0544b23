"""Readiness by name (ship_sim.ros.readiness, ship_sim.ros.held_start, ship_mission.ready_wait)
without DDS: endpoint listings and matched counts are plain objects the test changes by hand."""
from types import SimpleNamespace

from ship_mission.ready_wait import wait_for_announced, wait_for_subscribers
from ship_sim.ros.held_start import HeldStart, held_publisher
from ship_sim.ros.readiness import (PeerWait, announced_name, full_name, missing_names,
                                    names_param, peer_wait, ready_message)

OWN = '/vessel_0'
AUTOPILOT, RECORDER = f'{OWN}/autopilot_node', '/mission_recorder'


def info(name):
    """A TopicEndpointInfo-like entry for the full node name ``name``."""
    ns, _, node = name.rpartition('/')
    return SimpleNamespace(node_name=node, node_namespace=ns or '/')


class Graph:
    """One topic's subscribers as discovery lists them, and the writer's matched count."""

    def __init__(self, topic):
        self.topic, self.listed, self.matched = topic, [], 0
        self.sent = []

    # the node's side
    def get_subscriptions_info_by_topic(self, topic):
        assert topic == self.topic
        return [info(n) for n in self.listed]

    def get_publishers_info_by_topic(self, topic):
        return self.get_subscriptions_info_by_topic(topic)

    # the publisher's side
    @property
    def topic_name(self):
        return self.topic

    def get_subscription_count(self):
        return self.matched

    def publish(self, msg):
        self.sent.append(msg)


def test_full_names_as_the_graph_lists_them():
    assert full_name('/vessel_0', 'autopilot_node') == AUTOPILOT
    assert full_name('vessel_0/', 'autopilot_node') == AUTOPILOT
    assert full_name('/', 'mission_recorder') == RECORDER
    assert full_name(None, 'traffic_node') == '/traffic_node'
    assert names_param(['']) == () and names_param([' /a ', '', '/b']) == ('/a', '/b')


def test_each_named_node_must_be_listed_and_the_count_must_cover_the_listing():
    infos = [info(AUTOPILOT)]
    # the recorder has not been discovered at all: named as missing, whatever the count
    assert peer_wait([AUTOPILOT, RECORDER], infos, matched=5) == f'waiting for {RECORDER}'
    infos.append(info(RECORDER))
    # both listed, only one matched by the writer: not ready, and the listing is named
    text = peer_wait([AUTOPILOT, RECORDER], infos, matched=1)
    assert text is not None and '1 of 2' in text and RECORDER in text and AUTOPILOT in text
    assert peer_wait([AUTOPILOT, RECORDER], infos, matched=2) is None
    # an extra listed reader (an echo) is waited for too: the count cannot say who matched
    infos.append(info('/echo'))
    assert peer_wait([AUTOPILOT, RECORDER], infos, matched=2) is not None
    assert peer_wait([AUTOPILOT, RECORDER], infos, matched=3) is None


def test_a_wrong_named_subscriber_does_not_satisfy_the_wait():
    wrong = [info('/vessel_1/autopilot_node'), info(f'{OWN}/autopilot')]
    assert missing_names([AUTOPILOT], wrong) == [AUTOPILOT]
    assert peer_wait([AUTOPILOT], wrong, matched=2) == f'waiting for {AUTOPILOT}'
    # a count-only wait (no names) is satisfied by anyone: the weakness names remove
    assert peer_wait([], wrong, matched=2) is None
    assert peer_wait([], [], matched=0) == 'waiting for 1 subscribers (none listed)'


def test_a_late_joining_named_subscriber_opens_the_wait_once_matched():
    g = Graph(f'{OWN}/heading_cmd')
    wait = PeerWait(g, g, [AUTOPILOT, RECORDER])
    assert wait.is_writer and not wait.ready()
    assert wait.describe() == f'{OWN}/heading_cmd: waiting for {AUTOPILOT}, {RECORDER}'
    g.listed, g.matched = [RECORDER], 1
    assert wait.describe() == f'{OWN}/heading_cmd: waiting for {AUTOPILOT}'
    g.listed.append(AUTOPILOT)           # discovered by this node, not yet matched by the writer
    assert not wait.ready()
    g.matched = 2
    assert wait.ready() and wait.describe() == f'{OWN}/heading_cmd: ready'


class Node:
    """What HeldStart uses of an rclpy node: timers (never fired here), a logger."""

    def __init__(self):
        self.warnings = []

    def create_timer(self, period, callback, clock=None):
        return object()

    def destroy_timer(self, timer):
        pass

    def get_logger(self):
        return SimpleNamespace(warning=self.warnings.append)


class HeldGraph(Node, Graph):
    def __init__(self, topic):
        Node.__init__(self)
        Graph.__init__(self, topic)


def test_held_start_keeps_the_first_messages_until_the_named_reader_matched():
    g = HeldGraph(f'{OWN}/heading_cmd')
    held = HeldStart(g, g, names=[AUTOPILOT])
    g.listed, g.matched = ['/echo'], 1   # a reader, but not the one that pairs the commands
    for k in range(3):
        held.publish(SimpleNamespace(data=float(k)))
    assert g.sent == [] and len(held.queue) == 3
    g.listed.append(AUTOPILOT)
    held._poll()
    assert g.sent == []                  # listed, not matched yet
    g.matched = 2
    held._poll()
    assert [m.data for m in g.sent] == [0.0, 1.0, 2.0] and held.open
    held.publish(SimpleNamespace(data=3.0))
    assert [m.data for m in g.sent][-1] == 3.0 and not held.queue


def test_held_start_opens_after_its_timeout_naming_who_is_missing():
    g = HeldGraph(f'{OWN}/rudder_cmd')
    held = HeldStart(g, g, names=[f'{OWN}/vessel_node'], timeout_s=0.0)
    held.publish(SimpleNamespace(data=0.5))
    assert held.open and len(g.sent) == 1
    assert len(g.warnings) == 1 and f'waiting for {OWN}/vessel_node' in g.warnings[0]


def test_held_publisher_only_with_names():
    g = HeldGraph(f'{OWN}/heading_cmd')
    assert held_publisher(g, g, ['']) is g
    assert isinstance(held_publisher(g, g, [AUTOPILOT]), HeldStart)


def test_announcements_name_their_node():
    assert announced_name(ready_message('/traffic_node', ['/target_1/odom'])) == '/traffic_node'
    assert announced_name('not json') is None and announced_name('[1]') is None


class Monitor:
    """The launcher's node: a listing that grows by one name per spin."""

    def __init__(self, joining, topic='/clock'):
        self.joining, self.listed = list(joining), []
        self.node = SimpleNamespace(get_subscriptions_info_by_topic=lambda t: [
            info(n) for n in self.listed])

    def spin(self, seconds):
        if self.joining:
            self.listed.append(self.joining.pop(0))


def test_the_launcher_waits_for_names_and_returns_the_late_ones():
    m = Monitor(['/ais_node', '/vessel_0/colav_node', '/traffic_node'])
    assert wait_for_subscribers(m, '/clock', ['/traffic_node'], lambda: None, 5.0) == []
    assert m.listed[-1] == '/traffic_node'
    stuck = Monitor([])
    assert wait_for_subscribers(stuck, '/clock', ['/traffic_node'], lambda: None, 0.05) == [
        '/traffic_node']
    # check() true (a process died): the wait ends at once, without an answer
    assert wait_for_subscribers(stuck, '/clock', ['/traffic_node'], lambda: True, 5.0) is None


def test_the_launcher_waits_for_announcements_by_name():
    callbacks = []

    class AnnouncingMonitor:
        def __init__(self, texts):
            self.texts = list(texts)
            self.node = SimpleNamespace(
                create_subscription=lambda typ, topic, cb, qos: callbacks.append(cb) or cb,
                destroy_subscription=lambda sub: None)

        def spin(self, seconds):
            if self.texts:
                callbacks[-1](SimpleNamespace(data=self.texts.pop(0)))

    m = AnnouncingMonitor([ready_message('/ais_node', []), ready_message('/other', []),
                           ready_message('/traffic_node', [])])
    assert wait_for_announced(m, ['/traffic_node', '/ais_node'], lambda: None, 5.0) == []
    late = wait_for_announced(AnnouncingMonitor([ready_message('/ais_node', [])]),
                              ['/traffic_node', '/ais_node'], lambda: None, 0.05)
    assert late == ['/traffic_node']
