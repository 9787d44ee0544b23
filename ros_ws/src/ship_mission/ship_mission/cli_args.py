"""Command-line arguments of the project's tools, checked by argparse itself.

A number that is not finite or out of range, or an output folder that cannot be one, is refused
while the arguments are parsed, before a tool creates anything: one line
``<prog>: error: argument --x: <what>`` on stderr and exit code 2 (OneLineParser; argparse's
own error() prints the whole usage first).

    ap = OneLineParser(description=...)
    ap.add_argument('--duration', type=number(above=0.0, hi=1e5), default=2000.0)
    ap.add_argument('--jobs', type=integer(1, 64), default=2)
    ap.add_argument('--out', type=out_folder, default=Path('runs'))
"""
import argparse
import math
from pathlib import Path


class OneLineParser(argparse.ArgumentParser):
    """argparse.ArgumentParser whose refusals are one line (no usage), exit code 2."""

    def error(self, message):
        self.exit(2, f'{self.prog}: error: {" ".join(str(message).split())}\n')


def _bounds_text(lo, hi, above):
    def fmt(v):
        return str(v) if isinstance(v, int) else f'{v:g}'
    parts = []
    if above is not None:
        parts.append(f'> {fmt(above)}')
    elif lo is not None:
        parts.append(f'>= {fmt(lo)}')
    if hi is not None:
        parts.append(f'<= {fmt(hi)}')
    return ' and '.join(parts)


def number(lo=None, hi=None, *, above=None):
    """type= for a finite float within [lo, hi] (``above``: strictly greater than it)."""
    def parse(text):
        try:
            v = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f'a number expected, got {text!r}') from None
        bounds = _bounds_text(lo, hi, above)
        if not math.isfinite(v) or (above is not None and not v > above) \
                or (lo is not None and v < lo) or (hi is not None and v > hi):
            raise argparse.ArgumentTypeError(
                f'must be a finite number{" " + bounds if bounds else ""}, got {text}')
        return v
    return parse


def integer(lo=None, hi=None):
    """type= for an integer within [lo, hi]."""
    def parse(text):
        try:
            v = int(text) if len(text) <= 30 else None
        except ValueError:
            v = None
        bounds = _bounds_text(lo, hi, None)
        if v is None or (lo is not None and v < lo) or (hi is not None and v > hi):
            shown = text if len(text) <= 30 else text[:27] + '...'
            raise argparse.ArgumentTypeError(
                f'must be an integer{" " + bounds if bounds else ""}, got {shown!r}')
        return v
    return parse


def comma_names(choices):
    """argparse type: a comma-separated list of names, each one of ``choices``."""
    def parse(text):
        out = [v.strip() for v in text.split(',') if v.strip()]
        bad = [v for v in out if v not in choices]
        if bad:
            raise argparse.ArgumentTypeError(f'unknown {bad}; choose from {", ".join(choices)}')
        return out
    return parse


def out_folder(text):
    """type= for an output folder, created later: refused if it or the nearest existing
    parent is not a folder (a file there would end the tool in a traceback after its work)."""
    path = Path(text)
    for p in (path, *path.parents):
        if p.exists() or p.is_symlink():
            if not p.is_dir():
                what = 'it' if p == path else f'{p}'
                raise argparse.ArgumentTypeError(f'{text}: {what} exists and is not a folder')
            break
    return path
