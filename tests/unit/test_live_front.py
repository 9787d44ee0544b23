"""ship_mission.live_front against a stand-in for the foxglove-sdk server that behaves as the sdk does:
only the new subprotocol names, and a subscription that arrives before the sdk has entered a
just-advertised channel in its table refused with ``Unknown channel ID``."""
import asyncio
import json
import socket
import struct
import threading
import time

import pytest

from ship_mission.live_front import OLD_SUBPROTOCOL, SDK_SUBPROTOCOLS, SubprotocolFront


class _Sdk:
    """Advertises channels 1 and 2; refuses the first subscription of channel 1 (the race),
    then sends one message per subscription; refuses channel 9, never advertised."""

    def __init__(self):
        self.seen = {'subprotocols': [], 'subscribes': []}
        self.port = None
        self._ready, self._stop = threading.Event(), threading.Event()
        self._thread = threading.Thread(target=lambda: asyncio.run(self._main()), daemon=True)
        self._thread.start()
        assert self._ready.wait(10)

    async def _main(self):
        from websockets.asyncio.server import serve
        async with serve(self._client, '127.0.0.1', 0, subprotocols=[SDK_SUBPROTOCOLS[0]]) as srv:
            self.port = srv.sockets[0].getsockname()[1]
            self._ready.set()
            while not self._stop.is_set():
                await asyncio.sleep(0.02)

    async def _client(self, ws):
        self.seen['subprotocols'].append(ws.subprotocol)
        await ws.send(json.dumps({'op': 'advertise', 'channels': [
            {'id': 1, 'topic': '/a'}, {'id': 2, 'topic': '/b'}]}))
        refused_once = False
        async for text in ws:
            msg = json.loads(text)
            for sub in msg.get('subscriptions', ()):
                ch = sub['channelId']
                self.seen['subscribes'].append(ch)
                if ch == 9 or (ch == 1 and not refused_once):
                    refused_once = refused_once or ch == 1
                    await ws.send(json.dumps({'op': 'status', 'level': 2,
                                              'message': f'Unknown channel ID: {ch}'}))
                else:
                    await ws.send(struct.pack('<BIQ', 1, sub['id'], 123) + b'payload')

    def close(self):
        self._stop.set()
        self._thread.join(10)


@pytest.fixture
def front():
    sdk = _Sdk()
    f = SubprotocolFront('127.0.0.1', 0, f'ws://127.0.0.1:{sdk.port}')
    yield f, sdk
    f.close()
    sdk.close()


async def _session(port, subprotocol, subscribe):
    """Connect, subscribe ``subscribe`` (channel ids) after the advertisement, and collect what
    comes for 1 s."""
    from websockets.asyncio.client import connect
    got = []
    async with connect(f'ws://127.0.0.1:{port}', subprotocols=[subprotocol]) as ws:
        got.append(json.loads(await ws.recv()))
        await ws.send(json.dumps({'op': 'subscribe', 'subscriptions': [
            {'id': i, 'channelId': ch} for i, ch in enumerate(subscribe)]}))
        try:
            while True:
                frame = await asyncio.wait_for(ws.recv(), timeout=1.0)
                got.append(json.loads(frame) if isinstance(frame, str) else frame)
        except asyncio.TimeoutError:
            pass
        return ws.subprotocol, got


@pytest.mark.timeout(60)
@pytest.mark.parametrize('subprotocol', [OLD_SUBPROTOCOL, SDK_SUBPROTOCOLS[0]])
def test_a_refused_subscription_of_an_advertised_channel_is_sent_again(front, subprotocol):
    f, sdk = front
    chosen, got = asyncio.run(_session(f.port, subprotocol, [1, 2]))
    assert chosen == subprotocol and sdk.seen['subprotocols'] == [SDK_SUBPROTOCOLS[0]]
    assert got[0]['op'] == 'advertise'
    data = sorted(g for g in got[1:] if isinstance(g, bytes))
    # One message on each subscription (ids 0 and 1), and the refusal never reached the client.
    assert data == sorted(struct.pack('<BIQ', 1, i, 123) + b'payload' for i in (0, 1))
    assert not [g for g in got[1:] if isinstance(g, dict)], got
    assert sorted(sdk.seen['subscribes']) == [1, 1, 2] and f.retried == 1


@pytest.mark.timeout(60)
def test_the_refusal_of_a_channel_never_advertised_reaches_the_client(front):
    f, sdk = front
    _, got = asyncio.run(_session(f.port, OLD_SUBPROTOCOL, [9]))
    assert [g for g in got[1:]] == [{'op': 'status', 'level': 2,
                                     'message': 'Unknown channel ID: 9'}]
    assert sdk.seen['subscribes'] == [9] and f.retried == 0


@pytest.mark.timeout(60)
def test_a_client_without_a_foxglove_subprotocol_is_refused(front):
    from websockets.asyncio.client import connect
    from websockets.exceptions import InvalidStatus
    f, _ = front

    async def other():
        async with connect(f'ws://127.0.0.1:{f.port}', subprotocols=['chat']):
            pass
    with pytest.raises(InvalidStatus):
        asyncio.run(other())


def test_a_port_in_use_is_refused_with_the_reason():
    from ship_mission.live_front import FrontError
    with socket.socket() as taken:
        taken.bind(('127.0.0.1', 0))
        taken.listen()
        with pytest.raises(FrontError, match='address already in use'):
            SubprotocolFront('127.0.0.1', taken.getsockname()[1], 'ws://127.0.0.1:1')


@pytest.mark.timeout(120)
def test_with_the_real_sdk_every_channel_created_while_a_client_listens_is_subscribed():
    """The sdk itself behind the front: channels created one after another while a client that
    subscribes each at its advertisement is connected (directly, a few percent of them are
    refused on a busy machine); through the front every one ends up subscribed and no refusal
    reaches the client."""
    import foxglove
    from websockets.asyncio.client import connect
    n = 150
    ctx = foxglove.Context()
    server = foxglove.start_server(name='race', host='127.0.0.1', port=0, context=ctx)
    f = SubprotocolFront('127.0.0.1', 0, f'ws://127.0.0.1:{server.port}')
    seen = {'advertised': 0, 'errors': []}
    connected, done = threading.Event(), threading.Event()

    async def client():
        async with connect(f'ws://127.0.0.1:{f.port}', subprotocols=[OLD_SUBPROTOCOL]) as ws:
            connected.set()
            while not done.is_set():
                try:
                    text = await asyncio.wait_for(ws.recv(), 0.2)
                except asyncio.TimeoutError:
                    continue
                msg = json.loads(text) if isinstance(text, str) else {}
                if msg.get('op') == 'advertise':
                    subs = [{'id': seen['advertised'] + i, 'channelId': c['id']}
                            for i, c in enumerate(msg['channels'])]
                    seen['advertised'] += len(subs)
                    await ws.send(json.dumps({'op': 'subscribe', 'subscriptions': subs}))
                elif msg.get('op') == 'status':
                    seen['errors'].append(msg)
    thread = threading.Thread(target=lambda: asyncio.run(client()), daemon=True)
    thread.start()
    try:
        assert connected.wait(10)
        channels = []
        for i in range(n):
            channels.append(foxglove.Channel(f'/t{i}', schema={'type': 'object'}, context=ctx))
            time.sleep(0.005)
        deadline = time.monotonic() + 30.0
        while not all(c.has_sinks() for c in channels) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert seen['advertised'] == n
        assert sum(c.has_sinks() for c in channels) == n, f'{f.retried} re-sent'
        assert seen['errors'] == []
    finally:
        done.set()
        thread.join(10)
        f.close()
        server.stop()
