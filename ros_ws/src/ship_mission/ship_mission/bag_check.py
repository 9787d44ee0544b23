"""Read a bag with two independent readers and compare both with its metadata.yaml.

- the ``mcap`` library's reader (with CRC checks) and ``mcap-ros2-support``'s decoder, which
  parses the ros2msg schemas stored in the file (what Foxglove and other MCAP tools do);
- the project's own reader, rosbags' ``AnyReader`` (``ship_mission.bag``), which deserialises with
  the Jazzy typestore and the definitions the bag carries.

``cross_check`` returns per topic the message counts of metadata.yaml, of the first reader
(every message decoded) and of the second (every message deserialised), and the problems
found (empty when the three agree and everything decodes). The chunk compressions are listed
from the MCAP summary.
"""
from pathlib import Path

import yaml
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore


def metadata_counts(bag_dir):
    """{topic: message_count} of a bag's metadata.yaml."""
    info = yaml.safe_load((Path(bag_dir) / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    return {t['topic_metadata']['name']: t['message_count'] for t in info['topics_with_message_count']}


def mcap_counts(bag_dir):
    """({topic: messages decoded by mcap-ros2-support}, {chunk compressions}) of every MCAP
    file of the bag, reading with CRC validation."""
    counts, compressions = {}, set()
    for path in sorted(Path(bag_dir).glob('*.mcap')):
        with open(path, 'rb') as f:
            reader = make_reader(f, validate_crcs=True, decoder_factories=[DecoderFactory()])
            summary = reader.get_summary()
            compressions |= {c.compression for c in summary.chunk_indexes}
            for c in summary.channels.values():
                counts.setdefault(c.topic, 0)
            for _schema, channel, _msg, decoded in reader.iter_decoded_messages(log_time_order=False):
                if decoded is not None:
                    counts[channel.topic] += 1
    return counts, compressions


def rosbags_counts(bag_dir):
    """{topic: messages deserialised by rosbags' AnyReader}."""
    counts = {}
    with AnyReader([Path(bag_dir)], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        for c in reader.connections:
            counts.setdefault(c.topic, 0)
        for conn, _t, raw in reader.messages():
            reader.deserialize(raw, conn.msgtype)
            counts[conn.topic] += 1
    return counts


def cross_check(bag_dir):
    """-> {'metadata': counts, 'mcap': counts, 'rosbags': counts, 'compressions': set,
    'problems': [one line each]}."""
    meta = metadata_counts(bag_dir)
    by_mcap, compressions = mcap_counts(bag_dir)
    by_rosbags = rosbags_counts(bag_dir)
    problems = [f'{topic}: metadata.yaml {meta.get(topic)}, mcap {by_mcap.get(topic)}, '
                f'rosbags {by_rosbags.get(topic)}'
                for topic in sorted(set(meta) | set(by_mcap) | set(by_rosbags))
                if not meta.get(topic) == by_mcap.get(topic) == by_rosbags.get(topic)]
    return {'metadata': meta, 'mcap': by_mcap, 'rosbags': by_rosbags,
            'compressions': compressions, 'problems': problems}
