"""ship_mission.domain: the per-user lock directory is refused unless it is ours alone, lock files
are never opened through a symlink, and a full directory names who holds the ids."""
import os
import subprocess
import sys
from pathlib import Path

import pytest

from ship_mission import domain
from ship_mission.domain import DOMAIN_IDS, DomainLease, NoFreeDomain, UnsafeLockDir

SCRIPTS = Path(__file__).resolve().parents[2] / 'scripts'


def test_a_new_lock_dir_is_made_private_and_leases_are_exclusive(tmp_path):
    locks = tmp_path / 'locks'
    with DomainLease(directory=locks) as first, DomainLease(directory=locks) as second:
        assert first.domain_id != second.domain_id
        assert first.domain_id in DOMAIN_IDS and second.domain_id in DOMAIN_IDS
        assert os.lstat(locks).st_mode & 0o777 == 0o700
        lock = locks / f'{first.domain_id}.lock'
        assert lock.stat().st_mode & 0o077 == 0   # no other user may open it
        assert lock.read_text().split() == [str(os.getpid())]


def test_a_symlinked_lock_dir_is_refused(tmp_path):
    target = tmp_path / 'elsewhere'
    target.mkdir(mode=0o700)
    (tmp_path / 'locks').symlink_to(target)
    with pytest.raises(UnsafeLockDir, match='symlink'):
        DomainLease(directory=tmp_path / 'locks')
    assert list(target.iterdir()) == []   # nothing was created through the link


@pytest.mark.parametrize('mode', [0o755, 0o770, 0o1777])
def test_a_lock_dir_others_can_enter_is_refused(tmp_path, mode):
    locks = tmp_path / 'locks'
    locks.mkdir()
    locks.chmod(mode)
    with pytest.raises(UnsafeLockDir, match=f'mode {mode:04o}'):
        DomainLease(directory=locks)
    assert list(locks.iterdir()) == []


def test_a_lock_dir_of_another_user_is_refused(tmp_path, monkeypatch):
    locks = tmp_path / 'locks'
    locks.mkdir(mode=0o700)
    owner = os.lstat(locks).st_uid
    monkeypatch.setattr(domain.os, 'getuid', lambda: owner + 1)   # we are someone else
    with pytest.raises(UnsafeLockDir, match=f'owned by uid {owner}'):
        DomainLease(directory=locks)


def test_a_symlinked_lock_file_is_refused(tmp_path):
    locks = tmp_path / 'locks'
    locks.mkdir(mode=0o700)
    victim = tmp_path / 'victim'
    victim.write_text('keep\n')
    for did in DOMAIN_IDS:   # whichever id the search starts at
        (locks / f'{did}.lock').symlink_to(victim)
    with pytest.raises(UnsafeLockDir, match='symlink'):
        DomainLease(directory=locks)
    assert victim.read_text() == 'keep\n'


def test_all_ids_taken_gives_one_line_naming_the_holder(tmp_path):
    locks = tmp_path / 'locks'
    holder = subprocess.Popen(
        [sys.executable, '-c', 'import sys\nfrom ship_mission.domain import DomainLease, DOMAIN_IDS\n'
         f'ls = [DomainLease(directory={str(locks)!r}) for _ in DOMAIN_IDS]\n'
         'print("held", flush=True)\nsys.stdin.read()'],
        cwd=SCRIPTS, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == 'held'
        with pytest.raises(NoFreeDomain) as err:
            DomainLease(directory=locks)
        msg = str(err.value)
        assert '\n' not in msg
        assert f'{len(DOMAIN_IDS)} held in {locks}' in msg
        assert f'pid {holder.pid} (' in msg and f'holds {len(DOMAIN_IDS)}' in msg
    finally:
        holder.stdin.close()
        holder.wait(timeout=10)
    with DomainLease(directory=locks) as lease:   # the holder's end freed them
        assert lease.domain_id in DOMAIN_IDS


def test_ids_refused_by_the_probe_are_counted(tmp_path):
    with pytest.raises(NoFreeDomain, match=f'none held .*{len(DOMAIN_IDS)} refused by the probe'):
        DomainLease(accept=lambda did: False, directory=tmp_path / 'locks')


def test_lock_dir_is_per_user(tmp_path):
    uid = os.getuid()
    assert domain.lock_dir({}) == Path(f'/tmp/shipnav-{uid}')
    runtime = tmp_path / 'run'
    runtime.mkdir(mode=0o700)
    assert domain.lock_dir({'XDG_RUNTIME_DIR': str(runtime)}) == runtime / 'shipnav'
    link = tmp_path / 'link'
    link.symlink_to(runtime)
    assert domain.lock_dir({'XDG_RUNTIME_DIR': str(link)}) == Path(f'/tmp/shipnav-{uid}')
    assert domain.lock_dir({'XDG_RUNTIME_DIR': 'relative'}) == Path(f'/tmp/shipnav-{uid}')


def test_run_mission_refuses_an_unsafe_lock_dir_in_one_line(tmp_path, monkeypatch):
    from ship_mission.launcher import MissionFailed, run_scenario
    from ship_mission.scenario import load_scenario
    bad = tmp_path / 'locks'
    bad.mkdir(mode=0o755)
    bad.chmod(0o755)
    monkeypatch.setattr(domain, 'lock_dir', lambda env=None: bad)
    scenario = load_scenario(SCRIPTS.parent / 'scenarios' / 'course_changes_004.yaml', 'course_change_30_pd_004')
    with pytest.raises(MissionFailed, match='^refusing the domain lock directory') as err:
        run_scenario(scenario, runs_root=tmp_path / 'runs', progress=lambda s: None)
    assert '\n' not in str(err.value)
