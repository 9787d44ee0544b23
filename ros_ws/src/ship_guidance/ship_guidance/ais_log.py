"""Recorded AIS logs -> timed NMEA sentences (pure): the formats the replay tools read.

A log is text, one NMEA 0183 sentence (``!AIVDM``, ``!AIVDO``, any talker) a line, in one of
three forms; blank lines and lines starting with ``#`` are skipped:

(a) replay      ``<t_s> <sentence>``: seconds on any clock (ship_guidance.ais.parse_replay's
                format, the one scripts/make_ais_replay.py writes).
(b) tag block   ``\\<tag block>*hh\\<sentence>``: an NMEA 4.0 (IEC 61162-1 ed. 4) tag block
                before the sentence, as shore networks and many receivers write them. The time
                is its ``c:`` field, UNIX time in seconds; a value of 1e11 or more is taken as
                milliseconds (1e11 s lies in the year 5138, 1e11 ms in 1973, before AIS). The
                ``*hh`` checksum of the tag block is checked.
(c) untimed     ``<sentence>`` alone on every line: timed at ``i / rate`` s for the i-th line,
                ``rate`` lines per second given by the user (there is no default). A later part
                of a multi-sentence message takes the time of the line before it (one
                transmission; ais.parse_replay's rule).

Why a fixed rate for (c) and not the UTC second a position report carries: that field is the
second within the minute only (0-59), so unwrapping it needs every gap in the log shorter than
half a minute, and static data and later parts carry none; a log without times has no honest
clock, and a rate the user states keeps that assumption visible in the command and in the
results (a wrong rate makes the reported positions disagree with the reported SOG, and the
tracker's estimate lies between the two).

In a timed log (a or b), a line without a time of its own takes the time of the line before
it: the later sentences of a ``g:`` group carry no ``c:``, and some receivers interleave lines
without a tag block. Such lines before the first timed one are refused (``no_time``).

One log is one form. Refused with ``LogFormatError`` (one line): forms (a) and (b) in one log
(two clocks), a log with no sentence in any form, untimed lines without a rate, and a rate
given for a timed log. Lines that cannot be used are counted in ``AisLog.rejected`` by reason
(``REJECT_REASONS``) and skipped; sentences themselves are not checked here (ais.AisTracker
does that: checksum, fields, payload).

Output: ``AisLog.sentences``, [(t, sentence)] sorted by time, stable, so that a message's
parts, which share a time, stay in their order. Receivers stamp with whole seconds and several
stations' streams are merged out of order, hence the sort.
"""
import io
import math
from collections import Counter
from dataclasses import dataclass, field
from functools import reduce

from ship_guidance.ais import later_part
from ship_sim.safe_load import InputError, open_regular_file

FORMS = ('replay', 'tag_block', 'untimed')
REJECT_REASONS = (
    'not_a_sentence',       # no '!' / '$' sentence where one must be
    'bad_tag_block',        # a tag block without its closing '\' or its '*hh'
    'tag_block_checksum',   # the tag block's '*hh' does not match its text
    'bad_time',             # a time field that is not a finite number (c: also not >= 0)
    'no_time',              # a line without time before the first timed line of a timed log
)
#: c: values at or above this are milliseconds (module docstring).
MILLISECONDS_FROM = 1e11


class LogFormatError(ValueError):
    """The log as a whole cannot be read unambiguously (one-line message)."""


@dataclass
class AisLog:
    """A read log: the timed sentences, their form, the lines read and rejected."""
    sentences: list                     # [(t_s, sentence)], time order
    form: str                           # one of FORMS
    lines: int = 0                      # non-blank, non-comment lines
    rejected: Counter = field(default_factory=Counter)
    #: Times given to lines without one (tag-block group parts, interleaved plain lines).
    inherited: int = 0

    @property
    def unix_time(self):
        """Whether the times are UNIX seconds (a tag-block log)."""
        return self.form == 'tag_block'


def nmea_checksum(text):
    """Two upper-case hex digits: XOR of the characters (NMEA 0183 and tag blocks alike)."""
    return '%02X' % reduce(lambda a, c: a ^ ord(c), text, 0)


def _is_sentence(text):
    return len(text) > 6 and text[0] in '!$'


def split_tag_block(line):
    """``\\<fields>*hh\\<sentence>`` -> (fields {key: value}, sentence); ValueError naming the
    reason ('bad_tag_block' or 'tag_block_checksum') when the tag block is not whole or wrong."""
    end = line.find('\\', 1)
    if end < 0:
        raise ValueError('bad_tag_block')
    body, star, check = line[1:end].rpartition('*')
    if not star or len(check) != 2:
        raise ValueError('bad_tag_block')
    if nmea_checksum(body) != check.upper():
        raise ValueError('tag_block_checksum')
    fields = {}
    for item in body.split(','):
        key, colon, value = item.partition(':')
        if not colon:
            raise ValueError('bad_tag_block')
        fields[key] = value
    return fields, line[end + 1:].strip()


def tag_time(value):
    """Seconds from a tag block's ``c:`` value (module docstring); ValueError if not a time."""
    t = float(value)
    if not (math.isfinite(t) and t >= 0.0):
        raise ValueError(value)
    return t / 1000.0 if t >= MILLISECONDS_FROM else t


def _classify(line):
    """(kind, time or None, sentence) of one line; kind 'replay', 'tag_block', 'plain' or a
    reject reason."""
    if line.startswith('\\'):
        try:
            fields, sentence = split_tag_block(line)
        except ValueError as exc:
            return str(exc), None, None
        if not _is_sentence(sentence):
            return 'not_a_sentence', None, None
        if 'c' not in fields:
            return 'tag_block', None, sentence     # a group's later part: time inherited
        try:
            return 'tag_block', tag_time(fields['c']), sentence
        except ValueError:
            return 'bad_time', None, None
    if _is_sentence(line):
        return 'plain', None, line
    head, _, rest = line.partition(' ')
    rest = rest.strip()
    try:
        t = float(head)
    except ValueError:
        return 'not_a_sentence', None, None
    if not _is_sentence(rest):
        return 'not_a_sentence', None, None
    if not math.isfinite(t):
        return 'bad_time', None, None
    return 'replay', t, rest


def read_log(lines, rate=None):
    """Lines of a log (str, newlines allowed) -> ``AisLog`` (module docstring).

    ``rate``: lines per second of an untimed log (form (c)); must be None for a timed one."""
    if rate is not None and not (math.isfinite(rate) and rate > 0.0):
        raise LogFormatError(f'the rate must be a number > 0 lines per second, got {rate}')
    rejected = Counter()
    rows = []                           # (kind, t, sentence)
    n = 0
    for line in lines:
        line = line.strip()
        if not line or line.startswith('#'):
            continue
        n += 1
        kind, t, sentence = _classify(line)
        if kind in REJECT_REASONS:
            rejected[kind] += 1
        else:
            rows.append((kind, t, sentence))
    timed = {kind for kind, t, _ in rows if t is not None}
    if timed == {'replay', 'tag_block'}:
        raise LogFormatError("the log mixes '<t_s> <sentence>' times with tag-block c: times "
                             '(two clocks); give one form')
    if not rows:
        raise LogFormatError(f'no line of the log is an NMEA sentence in a known form '
                             f'({n} lines read)')
    if not timed:
        if rate is None:
            raise LogFormatError('the log has no times (neither "<t_s> <sentence>" nor tag '
                                 'blocks with c:): give the rate its lines were received at, '
                                 'in lines per second')
        return AisLog(_untimed(rows, rate), 'untimed', n, rejected)
    if rate is not None:
        raise LogFormatError(f'the log has its own times ({timed.pop()} form): a rate is only '
                             f'for logs without times')
    out, inherited, last = [], 0, None
    for kind, t, sentence in rows:
        if t is None:
            if last is None:
                rejected['no_time'] += 1
                continue
            t = last
            inherited += 1
        out.append((t, sentence))
        last = t
    out.sort(key=lambda item: item[0])
    return AisLog(out, timed.pop(), n, rejected, inherited)


def _untimed(rows, rate):
    out, i = [], 0
    for _, _, sentence in rows:
        if i and later_part(sentence):
            out.append(((i - 1) / rate, sentence))
        else:
            out.append((i / rate, sentence))
            i += 1
    return out


def read_log_file(path, rate=None):
    """``read_log`` of a file, streamed (logs may be long); LogFormatError (one line, without
    the path: the caller names the file) if it is not a regular file or cannot be read. Bytes
    that are not ASCII become U+FFFD (NMEA is ASCII): their lines are rejected, not the log."""
    try:
        with io.TextIOWrapper(open_regular_file(path), encoding='ascii',
                              errors='replace') as f:
            return read_log(f, rate)
    except InputError as exc:
        raise LogFormatError(exc.detail) from None
    except OSError as exc:
        raise LogFormatError(exc.strerror or str(exc)) from None
