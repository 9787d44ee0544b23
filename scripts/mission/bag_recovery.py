"""Recover a bag whose recorder was killed: an MCAP file without summary, footer or metadata.yaml.

rosbag2 readers (rosbags, ``ros2 bag``) open a bag through its metadata.yaml, which the writer
writes only when it closes, and rosbags' MCAP reader also needs the file's footer. A recorder
ended by SIGKILL (or a machine that lost power) leaves neither. What it did write is intact up
to the last complete record: the MCAP format (github.com/foxglove/mcap, "MCAP format
specification") is a magic, then records of opcode (1 byte), length (uint64 LE) and body;
schemas (0x03), channels (0x04) and messages (0x05) stand at top level or inside chunks (0x06,
uncompressed as our recorder writes them, or zstd/lz4). ``recover_bag`` reads every complete
record, drops a truncated last one, and writes the messages again as a complete bag (the same
topics, types, QoS, type hashes and log times) in place of the broken file, which is kept
beside it as ``<name>.mcap.partial``. The recorder's custom data (time source, rudder limits)
comes from ``recording.yaml``, which the recorder writes when it opens a bag.
"""
import struct
import tempfile
from pathlib import Path

import yaml
from rosbags.rosbag2.metadata import parse_qos
from rosbags.rosbag2.storage_mcap import decompress

MAGIC = b'\x89MCAP0\r\n'
OP_SCHEMA, OP_CHANNEL, OP_MESSAGE, OP_CHUNK = 0x03, 0x04, 0x05, 0x06


class RecoveryError(RuntimeError):
    """The file is not an MCAP file, or holds no complete message."""


def _string(buf, pos):
    (n,) = struct.unpack_from('<I', buf, pos)
    return bytes(buf[pos + 4:pos + 4 + n]).decode(), pos + 4 + n


def _string_map(data):
    out, pos = {}, 0
    while pos < len(data):
        key, pos = _string(data, pos)
        value, pos = _string(data, pos)
        out[key] = value
    return out


def _records(buf, pos, end):
    """(opcode, body memoryview) of every complete record in buf[pos:end]; stops at a torn one."""
    while pos + 9 <= end:
        op = buf[pos]
        (length,) = struct.unpack_from('<Q', buf, pos + 1)
        body = pos + 9
        if body + length > end:
            return   # torn by the kill
        yield op, buf[body:body + length]
        pos = body + length


def scan(path):
    """Read what an MCAP file holds -> (schemas, channels, messages).

    schemas: {id: (name, encoding, text)}; channels: {id: (topic, schema id, message encoding,
    metadata dict)}; messages: [(channel id, log time ns, bytes)] in file order.
    """
    buf = memoryview(Path(path).read_bytes())
    if bytes(buf[:8]) != MAGIC:
        raise RecoveryError(f'{path}: not an MCAP file')
    schemas, channels, messages = {}, {}, []

    def visit(records):
        for op, body in records:
            if op == OP_SCHEMA:
                (sid,) = struct.unpack_from('<H', body, 0)
                name, pos = _string(body, 2)
                enc, pos = _string(body, pos)
                (n,) = struct.unpack_from('<I', body, pos)
                schemas[sid] = (name, enc, bytes(body[pos + 4:pos + 4 + n]).decode())
            elif op == OP_CHANNEL:
                cid, sid = struct.unpack_from('<HH', body, 0)
                topic, pos = _string(body, 4)
                enc, pos = _string(body, pos)
                (n,) = struct.unpack_from('<I', body, pos)
                channels[cid] = (topic, sid, enc, _string_map(body[pos + 4:pos + 4 + n]))
            elif op == OP_MESSAGE:
                cid, _seq, log_time = struct.unpack_from('<HIQ', body, 0)
                messages.append((cid, log_time, bytes(body[22:])))
            elif op == OP_CHUNK:
                (size,) = struct.unpack_from('<Q', body, 16)
                (crc,) = struct.unpack_from('<I', body, 24)
                compression, pos = _string(body, 28)
                (n,) = struct.unpack_from('<Q', body, pos)
                data = memoryview(decompress(bytes(body[pos + 8:pos + 8 + n]), compression, size, crc))
                visit(_records(data, 0, len(data)))

    visit(_records(buf, 8, len(buf)))
    return schemas, channels, messages


def needs_recovery(bag_dir):
    """True for a bag directory with an MCAP file but no metadata.yaml."""
    bag_dir = Path(bag_dir)
    return (bag_dir.is_dir() and not (bag_dir / 'metadata.yaml').exists()
            and any(bag_dir.glob('*.mcap')))


def recover_bag(bag_dir):
    """Rewrite the broken bag in ``bag_dir`` as a complete one; returns a one-line summary."""
    from mission.recorder import RECORDING_FILE, BagWriter
    bag_dir = Path(bag_dir)
    broken = next(bag_dir.glob('*.mcap'))
    schemas, channels, messages = scan(broken)
    if not channels:
        raise RecoveryError(f'{broken}: no complete channel record (the recorder wrote nothing '
                            'that can be read back)')
    custom = {}
    side = bag_dir / RECORDING_FILE
    if side.is_file():
        custom = (yaml.safe_load(side.read_text()) or {}).get('custom_data') or {}
    with tempfile.TemporaryDirectory(dir=bag_dir.parent, prefix='.recover-') as tmp:
        fresh = Path(tmp) / bag_dir.name
        with BagWriter(fresh, custom_data=custom, side_file=False) as writer:
            conns = {}
            for cid, (topic, sid, _enc, meta) in sorted(channels.items()):
                msgtype = schemas[sid][0] if sid in schemas else None
                if msgtype is None:
                    continue   # its schema record was torn off: nothing to decode it with
                qos = parse_qos(meta.get('offered_qos_profiles', '')) if meta.get('offered_qos_profiles') else []
                conns[cid] = writer.add_topic(topic, msgtype, qos, meta.get('topic_type_hash') or None)
            n = 0
            for cid, t_ns, data in messages:
                if cid in conns:
                    writer.write(conns[cid], t_ns, data)
                    n += 1
        broken.rename(broken.with_name(broken.name + '.partial'))
        for f in fresh.iterdir():
            f.rename(bag_dir / f.name)
    return (f'{bag_dir}: recovered an interrupted recording: {n} messages on {len(conns)} topics '
            f'(the torn end is lost; the original is kept as {broken.name}.partial)')
