"""What a results file says about the run that wrote it: command, commit, date, machine load."""
import datetime
import os
import shlex
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def _git(*args):
    try:
        return subprocess.run(['git', *args], cwd=REPO, capture_output=True, text=True,
                              timeout=10, check=True).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None


def provenance(argv=None):
    """A dict for the results file: the command (as typed, relative to the repository), the
    commit with ``+dirty`` when the work tree had changes, the UTC date, the 1-minute load
    average at the end of the run and the CPU count (figures that depend on load say so)."""
    argv = list(sys.argv if argv is None else argv)
    if argv and Path(argv[0]).is_absolute():
        try:
            argv[0] = str(Path(argv[0]).relative_to(REPO))
        except ValueError:
            pass
    commit = _git('rev-parse', '--short=10', 'HEAD')
    if commit and _git('status', '--porcelain', '--untracked-files=no'):
        commit += '+dirty'
    return {
        'command': '.venv/bin/python ' + shlex.join(argv),
        'commit': commit,
        'date_utc': datetime.datetime.now(datetime.timezone.utc).strftime('%Y-%m-%d %H:%M'),
        'load_1min': round(os.getloadavg()[0], 1),
        'cpus': os.cpu_count(),
    }


def provenance_line(prov):
    """The sentence a page shows under a generated table."""
    return (f"Generated from the run of `{prov['command']}` at commit `{prov['commit']}` on "
            f"{prov['date_utc']} UTC (1-minute load {prov['load_1min']} on {prov['cpus']} CPUs).")
