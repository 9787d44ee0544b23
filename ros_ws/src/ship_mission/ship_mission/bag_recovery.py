"""Recover a bag whose MCAP file lost its end: a killed recorder, a copy cut short.

rosbag2 readers (rosbags, ``ros2 bag``) open a bag through its metadata.yaml, which the writer
writes only when it closes, and they need the MCAP file's summary (its index and footer),
written last as well. A recorder ended by SIGKILL (or a machine that lost power) leaves
neither; a copy cut short keeps metadata.yaml but loses the summary. What was written before
the cut is intact up to the last complete record: schemas, channels and messages stand in
chunks (zstd, lz4 or uncompressed) that the recorder closes and flushes every second.
``needs_recovery`` is true whenever the summary cannot be read, with or without metadata.yaml.

``recover_bag`` reads every complete record with the ``mcap`` library's stream reader (which
decompresses chunks and checks their CRCs) until the torn end, and writes the messages again
as a complete bag (the same topics, types, QoS, type hashes, log times and chunk compression)
in place of the broken file, which is kept beside it as ``<name>.mcap.partial`` (a surviving
metadata.yaml as ``metadata.yaml.partial``). The recorder's custom data (time source, rudder
limits) comes from ``recording.yaml``, which the recorder writes when it opens a bag, else from
the surviving metadata.yaml. The new bag's custom data says that it was recovered (RECOVERED,
its report), where the record ends (END_NS, the last log time) and, when a metadata.yaml
survived, how many messages each topic had (EXPECTED, JSON): ``ship_mission.integrity`` reports
from them what is lost, so a recovered bag is never called complete.
"""
import json
import tempfile
from pathlib import Path

import yaml
from mcap.exceptions import EndOfFile
from mcap.reader import make_reader
from mcap.records import Channel, Message, Schema
from mcap.stream_reader import StreamReader
from rosbags.rosbag2.metadata import parse_qos

#: custom_data keys of a recovered bag (read by ship_mission.integrity)
RECOVERED = 'mission.recovered'
END_NS = 'mission.recovered_end_ns'
EXPECTED = 'mission.recovered_expected'
MAX_TOPICS_LISTED = 6
MAGIC = b'\x89MCAP0\r\n'   # an MCAP file's first and last 8 bytes


class RecoveryError(RuntimeError):
    """The file is not an MCAP file, or holds no complete channel."""


def summary_readable(mcap_path):
    """True when the MCAP file ends with its footer, magic and a summary that parses."""
    try:
        with open(mcap_path, 'rb') as f:
            f.seek(-len(MAGIC), 2)
            if f.read() != MAGIC:
                return False
            f.seek(0)
            return make_reader(f).get_summary() is not None
    except Exception:  # noqa: BLE001 - whatever fails to parse, the summary is not readable
        return False


def needs_recovery(bag_dir):
    """True for a bag directory with an MCAP file and no metadata.yaml, or an MCAP file whose
    summary is unreadable (metadata.yaml or not)."""
    bag_dir = Path(bag_dir)
    mcaps = sorted(bag_dir.glob('*.mcap')) if bag_dir.is_dir() else []
    if not mcaps:
        return False
    return not (bag_dir / 'metadata.yaml').exists() or not all(map(summary_readable, mcaps))


def scan(path):
    """Read what an MCAP file holds up to its torn end -> (schemas, channels, messages, stop).

    schemas: {id: (name, encoding, text)}; channels: {id: (topic, schema id, message encoding,
    metadata dict)}; messages: [(channel id, log time ns, bytes)] in file order; stop: why the
    reading ended (None at a clean end of the data).
    """
    schemas, channels, messages = {}, {}, []
    stop = None
    with open(path, 'rb') as f:
        if f.read(len(MAGIC)) != MAGIC:
            raise RecoveryError(f'{path}: not an MCAP file')
        f.seek(0)
        try:
            for rec in StreamReader(f, validate_crcs=True).records:
                if isinstance(rec, Schema):
                    schemas[rec.id] = (rec.name, rec.encoding, bytes(rec.data).decode())
                elif isinstance(rec, Channel):
                    channels[rec.id] = (rec.topic, rec.schema_id, rec.message_encoding, dict(rec.metadata))
                elif isinstance(rec, Message):
                    messages.append((rec.channel_id, rec.log_time, bytes(rec.data)))
        except EndOfFile:
            stop = 'the file ends inside a record'
        except Exception as err:  # noqa: BLE001 - a CRC mismatch, a garbled length or chunk:
            stop = f'{err}'        # the data is damaged from here on, what came before stands
    return schemas, channels, messages, stop


def _surviving_metadata(bag_dir):
    """(custom_data, {topic: message count}) of a metadata.yaml that survived, else ({}, None)."""
    meta = bag_dir / 'metadata.yaml'
    if not meta.is_file():
        return {}, None
    try:
        info = (yaml.safe_load(meta.read_text()) or {}).get('rosbag2_bagfile_information') or {}
        counts = {t['topic_metadata']['name']: int(t['message_count'])
                  for t in info.get('topics_with_message_count') or []}
    except (yaml.YAMLError, KeyError, TypeError, ValueError, AttributeError):
        return {}, None
    return dict(info.get('custom_data') or {}), counts


def recover_bag(bag_dir):
    """Rewrite the broken bag in ``bag_dir`` as a complete one; returns a one-line report."""
    from ship_mission.recorder import DEFAULT_COMPRESSION, RECORDING_FILE, BagWriter
    bag_dir = Path(bag_dir)
    broken = next(bag_dir.glob('*.mcap'))
    schemas, channels, messages, _stop = scan(broken)
    if not channels:
        raise RecoveryError(f'{broken}: no complete channel record (the recorder wrote nothing '
                            'that can be read back)')
    custom, expected = _surviving_metadata(bag_dir)
    compression = DEFAULT_COMPRESSION
    side = bag_dir / RECORDING_FILE
    if side.is_file():
        recording = yaml.safe_load(side.read_text()) or {}
        custom = recording.get('custom_data') or custom
        compression = recording.get('compression') or compression
    custom = {k: v for k, v in custom.items() if k not in (RECOVERED, END_NS, EXPECTED)}
    conn_topic = {cid: topic for cid, (topic, sid, _enc, _meta) in channels.items() if sid in schemas}
    got = {topic: 0 for topic in conn_topic.values()}
    end_ns = 0
    for cid, t_ns, _data in messages:
        if cid in conn_topic:
            got[conn_topic[cid]] += 1
            end_ns = max(end_ns, t_ns)
    n = sum(got.values())
    line = (f'{bag_dir}: recovered an interrupted recording: {n} messages on {len(got)} topics, '
            f'up to log time {end_ns / 1e9:.1f} s; ' + lost_text(expected, got)
            + f' (the original is kept as {broken.name}.partial)')
    custom = {**custom, RECOVERED: line, END_NS: str(end_ns)}
    if expected is not None:
        custom[EXPECTED] = json.dumps(expected, sort_keys=True)
    with tempfile.TemporaryDirectory(dir=bag_dir.parent, prefix='.recover-') as tmp:
        fresh = Path(tmp) / bag_dir.name
        with BagWriter(fresh, custom_data=custom, side_file=False, compression=compression) as writer:
            conns = {}
            for cid, (topic, sid, _enc, meta) in sorted(channels.items()):
                if sid not in schemas:
                    continue   # its schema record was torn off: nothing to decode it with
                qos = parse_qos(meta['offered_qos_profiles']) if meta.get('offered_qos_profiles') else []
                conns[cid] = writer.add_topic(topic, schemas[sid][0], qos, meta.get('topic_type_hash') or None)
            for cid, t_ns, data in messages:
                if cid in conns:
                    writer.write(conns[cid], t_ns, data)
        broken.rename(broken.with_name(broken.name + '.partial'))
        if (bag_dir / 'metadata.yaml').exists():
            (bag_dir / 'metadata.yaml').rename(bag_dir / 'metadata.yaml.partial')
        for f in fresh.iterdir():
            f.rename(bag_dir / f.name)
    return line


def lost(expected, got):
    """{topic: (received, expected)} of the topics with fewer messages than ``expected`` said."""
    return {t: (got.get(t, 0), e) for t, e in sorted((expected or {}).items()) if got.get(t, 0) < e}


def lost_text(expected, got):
    """What a recovery lost, in words: per topic from the surviving metadata.yaml's counts, or
    that it is not known."""
    if expected is None:
        return 'the end of the recording is lost (no metadata.yaml survived: how much is not known)'
    short = lost(expected, got)
    if not short:
        return 'no message is lost (every topic has the count metadata.yaml gives)'
    total = sum(e - g for g, e in short.values())
    parts = [f'{t} {e - g} of {e}' for t, (g, e) in list(short.items())[:MAX_TOPICS_LISTED]]
    more = len(short) - MAX_TOPICS_LISTED
    return (f'{total} of the messages metadata.yaml counts are lost at the end, per topic lost of '
            f'counted: {", ".join(parts)}' + (f' and {more} more topics' if more > 0 else ''))
