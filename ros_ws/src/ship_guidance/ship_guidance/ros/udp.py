"""Reading NMEA lines from a non-blocking UDP socket without starving the node (ais_node,
tracker_node).

A flood of datagrams must not keep a timer callback busy: one poll reads at most
UDP_MAX_DATAGRAMS and works at most UDP_POLL_BUDGET_S of wall time; the rest waits in the
kernel's buffer for the next poll (and is dropped there if the flood goes on).
"""
import time

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
