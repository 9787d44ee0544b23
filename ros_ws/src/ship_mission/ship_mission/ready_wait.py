"""The launcher's waits on the ROS graph, by node name (ship_sim.ros.readiness): until named
nodes subscribe a topic, and until named nodes have announced that they are ready.

Each wait spins the launcher's own node (``monitor``: ship_mission.launcher.Monitor), calls
``check()`` between spins (it raises, or returns true to end the wait early, returning None,
when a process has died) and returns the names still missing when ``timeout_s`` of wall time
ran out ([] when none): the caller says what that means for the run, naming them.
"""
import time

from ship_sim.ros.readiness import READY_TOPIC, announced_name, missing_names

POLL_S = 0.1


def wait_for_subscribers(monitor, topic, names, check, timeout_s):
    """Wait until every node of ``names`` (full names) subscribes ``topic``."""
    end = time.monotonic() + timeout_s
    while True:
        absent = missing_names(names, monitor.node.get_subscriptions_info_by_topic(topic))
        if not absent or time.monotonic() > end:
            return absent
        if check():
            return None
        monitor.spin(POLL_S)


def wait_for_announced(monitor, names, check, timeout_s):
    """Wait until every node of ``names`` has announced on READY_TOPIC that it is ready."""
    from std_msgs.msg import String

    from ship_sim.ros.qos import READY
    heard = set()
    sub = monitor.node.create_subscription(
        String, READY_TOPIC, lambda m: heard.add(announced_name(m.data)), READY)
    try:
        end = time.monotonic() + timeout_s
        while True:
            absent = [n for n in names if n not in heard]
            if not absent or time.monotonic() > end:
                return absent
            if check():
                return None
            monitor.spin(POLL_S)
    finally:
        monitor.node.destroy_subscription(sub)
