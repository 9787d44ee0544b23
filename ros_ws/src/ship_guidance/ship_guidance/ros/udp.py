"""Reading NMEA lines from a non-blocking UDP socket without starving the node (ais_node,
tracker_node).

A flood of datagrams must not keep a timer callback busy: one poll reads at most
UDP_MAX_DATAGRAMS and works at most UDP_POLL_BUDGET_S of wall time; the rest waits in the
kernel's buffer for the next poll (and is dropped there if the flood goes on).
"""
import socket
import time

from ship_sim.ros.params import ParameterError

UDP_POLL_S = 0.02          # wall-clock period of the UDP poll
UDP_MAX_DATAGRAMS = 500    # datagrams one poll reads at most ...
UDP_POLL_BUDGET_S = 0.01   # ... and wall time it works at most (half the poll period)


def udp_lines(sock, logger):
    """The non-empty lines (bytes) of the datagrams waiting on ``sock``, within one poll's
    bounds; a receive error is warned about (throttled) and ends the poll."""
    deadline = time.monotonic() + UDP_POLL_BUDGET_S
    for _ in range(UDP_MAX_DATAGRAMS):
        if time.monotonic() > deadline:
            return
        try:
            data = sock.recv(65536)
        except (BlockingIOError, InterruptedError):
            return
        except OSError as exc:
            logger.warning(f'UDP receive failed: {exc}', throttle_duration_sec=5.0)
            return
        for line in data.splitlines():
            if line.strip():
                yield line


def bind_udp(address, port):
    """A non-blocking UDP socket bound to (address, port); a port that cannot be bound is the
    node's parameter error (one line naming ``udp_port``)."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        sock.bind((address, port))
    except OSError as exc:
        sock.close()
        raise ParameterError('udp_port', port, f'a free UDP port on {address} '
                             f'({exc.strerror})') from None
    sock.setblocking(False)
    return sock
