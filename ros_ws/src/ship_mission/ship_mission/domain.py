"""ROS_DOMAIN_ID leases: one graph per domain for each user of this machine.

Other graphs with the same domain id (tests, other launchers, benchmarks) would mix their
messages into ours (a foreign route, rudder commands or odometry in a bag). Every user takes
an id through ``DomainLease``: an exclusive flock on <lock dir>/<id>.lock for ids in DOMAIN_IDS,
held until ``close()`` or the end of the process. The launcher, the integration tests' harness,
the seed-scenario batch and the benchmarks all lease here, so they never share an id.

The lock directory is per user (``lock_dir()``): ``$XDG_RUNTIME_DIR/shipnav`` when that is set
and ours, else ``/tmp/shipnav-<uid>``. It is created 0700 and refused unless it is a real
directory (not a symlink) owned by us with mode 0700; lock files are opened with O_NOFOLLOW
relative to that directory. A lock directory shared by all users (as before) let another user
make our leases fail (a directory we cannot write), hold every id through read-only descriptors,
or, with ``fs.protected_symlinks=0``, plant symlinks that made root create files elsewhere.

Different users therefore lease from different directories and can be given the same id. That
is accepted: the leases prevent accidents between one user's own runs and tests, they are no
security boundary (DDS has no access control without SROS2, so any local user can join any
domain anyway), and the search starts at an id derived from the pid, which is unique across
users, so two users' processes collide only when one holds many ids. A caller that must not
share its domain with anyone passes ``accept`` (the seed-scenario batch probes the domain for
other nodes). Processes of one user must agree on ``$XDG_RUNTIME_DIR`` (set or unset) to see
each other's leases; a login session and a cron job of the same user may differ.
"""
import errno
import fcntl
import os
import re
import stat
from pathlib import Path

DOMAIN_IDS = range(1, 102)   # Fast DDS ports stay below Linux's ephemeral range up to 101

_held = []   # leases of lease_domain_id, kept for the life of the process


class LeaseError(RuntimeError):
    """A domain id could not be leased; the message is one line for the user."""


class NoFreeDomain(LeaseError):
    """Every domain id is leased (or refused by ``accept``)."""


class UnsafeLockDir(LeaseError):
    """The lock directory or a lock file is not ours alone (owner, mode, symlink)."""


def lock_dir(env=None):
    """The per-user lock directory: ``$XDG_RUNTIME_DIR/shipnav`` when that variable names an
    absolute directory owned by us (not a symlink), else ``/tmp/shipnav-<uid>``."""
    env = os.environ if env is None else env
    xdg = env.get('XDG_RUNTIME_DIR', '')
    if os.path.isabs(xdg):
        try:
            st = os.lstat(xdg)
        except OSError:
            st = None
        if (st is not None and stat.S_ISDIR(st.st_mode) and st.st_uid == os.getuid()
                and os.access(xdg, os.W_OK | os.X_OK)):
            return Path(xdg) / 'shipnav'
    return Path('/tmp') / f'shipnav-{os.getuid()}'


def open_lock_dir(path):
    """A descriptor of the lock directory ``path``, made 0700 if missing; UnsafeLockDir unless
    it is a directory (not a symlink) owned by us with mode 0700."""
    created = False
    try:
        os.mkdir(path, 0o700)   # does not follow a symlink planted at ``path``
        created = True
    except FileExistsError:
        pass
    except OSError as exc:
        raise UnsafeLockDir(f'cannot create the domain lock directory {path}: '
                            f'{exc.strerror or exc}') from None
    try:
        fd = os.open(path, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | os.O_CLOEXEC)
    except OSError as exc:
        why = ('it is a symlink or not a directory' if exc.errno in (errno.ELOOP, errno.ENOTDIR)
               else exc.strerror or str(exc))
        raise UnsafeLockDir(f'refusing the domain lock directory {path}: {why}') from None
    try:
        st = os.fstat(fd)
        if st.st_uid != os.getuid():
            raise UnsafeLockDir(f'refusing the domain lock directory {path}: owned by uid '
                                f'{st.st_uid}, not by us (uid {os.getuid()}); remove it or '
                                f'set XDG_RUNTIME_DIR')
        if created and stat.S_IMODE(st.st_mode) != 0o700:
            os.fchmod(fd, 0o700)   # the umask took bits from the 0700 we asked for
        elif stat.S_IMODE(st.st_mode) != 0o700:
            raise UnsafeLockDir(f'refusing the domain lock directory {path}: mode '
                                f'{stat.S_IMODE(st.st_mode):04o}, not 0700 (chmod 700 it)')
    except BaseException:
        os.close(fd)
        raise
    return fd


def _open_lock_file(dir_fd, path, did):
    """A descriptor of ``<did>.lock`` in the directory ``dir_fd``; never through a symlink."""
    name = f'{did}.lock'
    try:
        fd = os.open(name, os.O_CREAT | os.O_RDWR | os.O_NOFOLLOW | os.O_CLOEXEC, 0o600,
                     dir_fd=dir_fd)
    except OSError as exc:
        why = 'it is a symlink' if exc.errno == errno.ELOOP else exc.strerror or str(exc)
        raise UnsafeLockDir(f'refusing the domain lock file {path / name}: {why}') from None
    st = os.fstat(fd)
    if not stat.S_ISREG(st.st_mode) or st.st_uid != os.getuid():
        os.close(fd)
        raise UnsafeLockDir(f'refusing the domain lock file {path / name}: not a regular file '
                            f'of ours')
    return fd


def _flock_holders(inodes):
    """{inode: pid} of the flock holders in /proc/locks for files with these inodes ({} when
    /proc/locks cannot be read)."""
    holders = {}
    try:
        text = Path('/proc/locks').read_text()
    except OSError:
        return holders
    # "1: FLOCK  ADVISORY  WRITE 12076 fe:00:2146442 0 EOF"; "-> " marks a blocked waiter
    for m in re.finditer(r'^\d+: (?!->)FLOCK\s+\S+\s+\S+\s+(\d+)\s+[0-9a-f]+:[0-9a-f]+:(\d+)\s',
                         text, re.MULTILINE):
        if int(m[2]) in inodes:
            holders.setdefault(int(m[2]), int(m[1]))
    return holders


def _process_name(pid):
    try:
        argv = Path(f'/proc/{pid}/cmdline').read_bytes().split(b'\0')
    except OSError:
        return '?'
    words = [os.path.basename(a.decode(errors='replace')) for a in argv[:2] if a]
    return ' '.join(words) or '?'


def _describe_holders(dir_fd, ids):
    """'pid 12 (python run_mission.py) holds 3, pid 40 (pytest) holds 1' for the lock files of
    ``ids``: the pid from /proc/locks, else the pid the holder wrote into its lock file."""
    inodes = {}
    for did in ids:
        try:
            inodes[os.stat(f'{did}.lock', dir_fd=dir_fd, follow_symlinks=False).st_ino] = did
        except OSError:
            pass
    by_inode = _flock_holders(set(inodes))
    counts = {}
    for ino, did in inodes.items():
        pid = by_inode.get(ino)
        if pid is None:
            try:
                fd = os.open(f'{did}.lock', os.O_RDONLY | os.O_NOFOLLOW, dir_fd=dir_fd)
                try:
                    pid = int(os.read(fd, 32).decode().strip() or 0) or None
                finally:
                    os.close(fd)
            except (OSError, ValueError):
                pid = None
        counts[pid] = counts.get(pid, 0) + 1
    parts = [f'pid {pid} ({_process_name(pid)}) holds {n}'
             for pid, n in sorted(counts.items(), key=lambda kv: -kv[1]) if pid is not None]
    if None in counts:
        parts.append(f'{counts[None]} by unknown holders')
    return ', '.join(parts) or 'holders unknown'


class DomainLease:
    """An exclusive ROS_DOMAIN_ID (``domain_id``) until ``close()`` (also a context manager).

    The search starts at an id derived from the pid, so concurrent processes rarely contend.
    ``accept(domain_id) -> bool`` may refuse a locked id (e.g. one on which a probe still sees
    nodes of a graph that does not lease); a refused id is released and the search goes on.
    ``directory`` defaults to ``lock_dir()``. Raises LeaseError (one-line message): NoFreeDomain
    naming the holders, or UnsafeLockDir.
    """

    def __init__(self, accept=None, directory=None):
        path = Path(lock_dir() if directory is None else directory)
        self.domain_id, self._fd = None, None
        dir_fd = open_lock_dir(path)
        try:
            taken, refused = [], []
            n = len(DOMAIN_IDS)
            for i in range(n):
                did = DOMAIN_IDS[(os.getpid() + i) % n]
                fd = _open_lock_file(dir_fd, path, did)
                try:
                    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                except OSError:
                    os.close(fd)
                    taken.append(did)
                    continue
                if accept is None or accept(did):
                    # Our pid in the file names the holder where /proc/locks is not readable.
                    os.ftruncate(fd, 0)
                    os.write(fd, f'{os.getpid()}\n'.encode())
                    self.domain_id, self._fd = did, fd
                    return
                os.close(fd)
                refused.append(did)
            held = f'{len(taken)} held in {path}: {_describe_holders(dir_fd, taken)}' \
                if taken else f'none held in {path}'
            probe = f'; {len(refused)} refused by the probe (other nodes on them)' \
                if refused else ''
            raise NoFreeDomain(f'no free ROS_DOMAIN_ID in {DOMAIN_IDS.start}..'
                               f'{DOMAIN_IDS.stop - 1}: {held}{probe}')
        finally:
            os.close(dir_fd)

    def close(self):
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def lease_domain_id():
    """A free ROS_DOMAIN_ID, leased for the life of this process (LeaseError if none)."""
    lease = DomainLease()
    _held.append(lease)
    return lease.domain_id
