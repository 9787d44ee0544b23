"""Readiness by name: an endpoint is ready for its topic once every node it must serve (or hear)
is listed on the topic by name and its own matched count covers the listing.

Counts carry no names: a publisher that waits for "3 subscribers" is satisfied by any three,
e.g. by an echo or a display while the node that pairs its messages by sequence has not been
discovered at all; that node then misses the first message and every later one is taken for the
step before it. Names from the graph (ship_mission.graph) say who must be there, and the
endpoint's own matched count says that it will also send to them: a reader listed by discovery
is not yet a reader the writer sends to (discovery is per endpoint), so (a) each named node must
be listed on the topic and (b) the count the endpoint itself keeps must reach the number of
endpoints listed. A listed endpoint that is not named (``ros2 topic echo``) is waited for too,
so (b) can be checked without knowing which ones have matched.

``peer_wait`` is the rule on plain values (no ROS); ``PeerWait`` applies it to a publisher (its
subscribers) or a subscription (its publishers); ``ReadyAnnouncer`` publishes a node's readiness
on the graph-wide READY_TOPIC, which the launcher waits on by name (ship_mission.ready_wait).
"""
import json

#: Where every node says, once, that it is ready for what it serves (std_msgs/String, JSON
#: ``{"node": full name, "ready_for": [what it waited for]}``; ship_sim.ros.qos.READY, so a
#: launcher that subscribes after the announcements still gets every one).
READY_TOPIC = '/graph_ready'


def full_name(namespace, name):
    """'/ns/name' (or '/name' in the root namespace): how the graph and the launcher name nodes."""
    ns = (namespace or '').strip('/')
    return f'/{ns}/{name}' if ns else f'/{name}'


def names_param(values):
    """The node names of a string-array parameter (``['']`` is the schema's "none"), in order."""
    return tuple(v.strip() for v in values if v and v.strip())


def listed_names(infos):
    """Full names of the endpoints ``infos`` (TopicEndpointInfo: node_name, node_namespace)."""
    return [full_name(i.node_namespace, i.node_name) for i in infos]


def missing_names(required, infos):
    """The names of ``required`` that no endpoint of ``infos`` belongs to, in their order."""
    listed = set(listed_names(infos))
    return [n for n in required if n not in listed]


def peer_wait(required, infos, matched, minimum=1, peers='subscribers'):
    """None when an endpoint that has matched ``matched`` peers is ready, else what it waits for
    (one phrase). ``required``: full node names that must be listed (empty: any ``minimum``
    peers will do, the count-only rule); ``infos``: the peers listed on the topic."""
    absent = missing_names(required, infos)
    if absent:
        return 'waiting for ' + ', '.join(absent)
    listed = listed_names(infos)
    need = max(len(listed), len(required) or minimum)
    if matched >= need:
        return None
    if not listed:
        return f'waiting for {need} {peers} (none listed)'
    return (f'{matched} of {need} {peers} matched (listed: '
            f"{', '.join(sorted(set(listed)))})")


class PeerWait:
    """``peer_wait`` for one endpoint of ``node``: a publisher waits for its subscribers, a
    subscription for its publishers."""

    def __init__(self, node, endpoint, names=(), minimum=1):
        self.node, self.endpoint = node, endpoint
        self.names, self.minimum = tuple(names), int(minimum)
        self.is_writer = hasattr(endpoint, 'get_subscription_count')

    @property
    def topic(self):
        return self.endpoint.topic_name

    def status(self):
        if self.is_writer:
            infos = self.node.get_subscriptions_info_by_topic(self.topic)
            matched = self.endpoint.get_subscription_count()
        else:
            infos = self.node.get_publishers_info_by_topic(self.topic)
            matched = self.endpoint.get_publisher_count()
        return peer_wait(self.names, infos, matched, self.minimum,
                         'subscribers' if self.is_writer else 'publishers')

    def ready(self):
        return self.status() is None

    def describe(self):
        """'<topic>: <what it waits for>', or '<topic>: ready'."""
        return f'{self.topic}: {self.status() or "ready"}'


def describe_waits(waits):
    """The waits not yet over, one '<topic>: ...' each, joined by '; '."""
    return '; '.join(w.describe() for w in waits if not w.ready())


def ready_message(node_name, ready_for):
    """The JSON text a node announces on READY_TOPIC."""
    return json.dumps({'node': node_name, 'ready_for': list(ready_for)}, sort_keys=True)


def announced_name(text):
    """The node name of an announcement (None if the text is not one)."""
    try:
        value = json.loads(text)
    except ValueError:
        return None
    return value.get('node') if isinstance(value, dict) else None


class ReadyAnnouncer:
    """Publishes ``node``'s readiness once on READY_TOPIC (each node's writer keeps its one
    announcement for late subscribers)."""

    def __init__(self, node):
        from std_msgs.msg import String

        from ship_sim.ros.qos import READY
        self.node, self.done = node, False
        self._msg_type = String
        self.pub = node.create_publisher(String, READY_TOPIC, READY)

    @property
    def name(self):
        return full_name(self.node.get_namespace(), self.node.get_name())

    def announce(self, ready_for=()):
        if self.done:
            return
        self.done = True
        self.pub.publish(self._msg_type(data=ready_message(self.name, ready_for)))
