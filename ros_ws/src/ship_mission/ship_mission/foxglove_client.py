"""A minimal Foxglove WebSocket protocol client (foxglove.websocket.v1), for tests and benchmarks.

What a viewer does, from the protocol spec (foxglove/ws-protocol, "spec.md"): connect with the
subprotocol ``foxglove.websocket.v1`` or its new name ``foxglove.sdk.v1`` (the same protocol;
foxglove-sdk servers and foxglove_bridge 3.x accept only the new name); the server sends JSON
text frames (``serverInfo``, ``advertise`` with each channel's id, topic, encoding, schemaName, schema, schemaEncoding);
the client answers ``{"op": "subscribe", "subscriptions": [{"id", "channelId"}]}``; messages
then come as binary frames: opcode 0x01, uint32 subscription id, uint64 log time (ns), the
payload; opcode 0x02 is the server's time (uint64 ns). All little endian.

``FoxgloveClient`` runs the connection in a thread (asyncio + the websockets package),
subscribes the wanted topics as soon as they are advertised, and keeps what arrives. With
``read_delay_s`` it sleeps after every frame: a slow client, to check that the server drops for
it instead of holding anything back.
"""
import asyncio
import json
import struct
import threading
import time

SUBPROTOCOLS = ['foxglove.sdk.v1', 'foxglove.websocket.v1']
MESSAGE_DATA = 0x01
TIME = 0x02
_HEADER = struct.Struct('<BIQ')


class FoxgloveClient:
    """Connect to ``url`` (retrying until ``connect_timeout_s``) and subscribe ``topics``
    (None: every advertised topic). ``channels``: topic -> the advertised channel (a dict);
    ``messages``: topic -> [(log_time_ns, payload bytes)]; ``server_time_ns``: the last time
    broadcast; ``error``: why the connection ended early, if it did."""

    def __init__(self, url, topics=None, connect_timeout_s=60.0, read_delay_s=0.0):
        self.url = url
        self.topics = None if topics is None else set(topics)
        self.connect_timeout_s = connect_timeout_s
        self.read_delay_s = read_delay_s
        self.channels = {}
        self.messages = {}
        self.server_info = None
        self.server_time_ns = None
        self.error = None
        self.connected = threading.Event()
        self._subscribed = {}     # subscription id -> topic
        self._stop = threading.Event()
        self._thread = threading.Thread(target=lambda: asyncio.run(self._run()), daemon=True)
        self._thread.start()

    def close(self, timeout=10.0):
        self._stop.set()
        self._thread.join(timeout)

    def count(self, topic):
        return len(self.messages.get(topic, ()))

    async def _connect(self):
        from websockets.asyncio.client import connect
        deadline = time.monotonic() + self.connect_timeout_s
        while True:
            try:
                return await connect(self.url, subprotocols=SUBPROTOCOLS, max_size=None,
                                     open_timeout=5.0)
            except OSError:
                if time.monotonic() > deadline or self._stop.is_set():
                    raise
                await asyncio.sleep(0.2)

    async def _run(self):
        try:
            ws = await self._connect()
        except Exception as exc:  # noqa: BLE001 - reported to the caller
            self.error = f'cannot connect to {self.url}: {exc}'
            return
        self.connected.set()
        try:
            while not self._stop.is_set():
                try:
                    frame = await asyncio.wait_for(ws.recv(), timeout=0.1)
                except asyncio.TimeoutError:
                    continue
                if isinstance(frame, str):
                    await self._on_text(ws, json.loads(frame))
                else:
                    self._on_binary(frame)
                if self.read_delay_s:
                    await asyncio.sleep(self.read_delay_s)
        except Exception as exc:  # noqa: BLE001 - the server went away: reported, not raised
            if not self._stop.is_set():
                self.error = f'connection ended: {exc}'
        finally:
            await ws.close()

    async def _on_text(self, ws, msg):
        op = msg.get('op')
        if op == 'serverInfo':
            self.server_info = msg
        elif op == 'advertise':
            subs = []
            for ch in msg['channels']:
                topic = ch['topic']
                if topic in self.channels or (self.topics is not None and topic not in self.topics):
                    continue
                self.channels[topic] = ch
                sub_id = len(self._subscribed) + 1
                self._subscribed[sub_id] = topic
                subs.append({'id': sub_id, 'channelId': ch['id']})
            if subs:
                await ws.send(json.dumps({'op': 'subscribe', 'subscriptions': subs}))

    def _on_binary(self, frame):
        if frame[0] == MESSAGE_DATA:
            _, sub_id, log_time = _HEADER.unpack_from(frame, 0)
            topic = self._subscribed.get(sub_id)
            if topic is not None:
                self.messages.setdefault(topic, []).append((log_time, bytes(frame[_HEADER.size:])))
        elif frame[0] == TIME:
            self.server_time_ns = struct.unpack_from('<Q', frame, 1)[0]
