"""ROS_DOMAIN_ID leases: one graph per domain on this machine.

Other graphs with the same domain id (tests, other launchers, benchmarks) would mix their
messages into ours (a foreign route, rudder commands or odometry in a bag). Every user takes
an id through ``DomainLease``: an exclusive flock on LOCK_DIR/<id>.lock for ids in DOMAIN_IDS,
held until ``close()`` or the end of the process. The launcher, the integration tests' harness,
the seed-scenario batch and the benchmarks all lease here, so they never share an id.
"""
import fcntl
import os
from pathlib import Path

LOCK_DIR = Path('/tmp/shipnav_ros_domain_locks')
DOMAIN_IDS = range(1, 102)   # Fast DDS ports stay below Linux's ephemeral range up to 101

_held = []   # leases of lease_domain_id, kept for the life of the process


class NoFreeDomain(RuntimeError):
    """Every domain id is leased (or refused by ``accept``)."""


class DomainLease:
    """An exclusive ROS_DOMAIN_ID (``domain_id``) until ``close()`` (also a context manager).

    The search starts at an id derived from the pid, so concurrent processes rarely contend.
    ``accept(domain_id) -> bool`` may refuse a locked id (e.g. one on which a probe still sees
    nodes of a graph that does not lease); a refused id is released and the search goes on.
    """

    def __init__(self, accept=None):
        LOCK_DIR.mkdir(parents=True, exist_ok=True)
        self.domain_id, self._fd = None, None
        n = len(DOMAIN_IDS)
        for i in range(n):
            did = DOMAIN_IDS[(os.getpid() + i) % n]
            fd = os.open(LOCK_DIR / f'{did}.lock', os.O_CREAT | os.O_RDWR, 0o666)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                os.close(fd)
                continue
            if accept is None or accept(did):
                self.domain_id, self._fd = did, fd
                return
            os.close(fd)
        raise NoFreeDomain(f'no free ROS_DOMAIN_ID in {DOMAIN_IDS} (locks in {LOCK_DIR})')

    def close(self):
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def lease_domain_id():
    """A free ROS_DOMAIN_ID, leased for the life of this process."""
    lease = DomainLease()
    _held.append(lease)
    return lease.domain_id
