"""The live view's public WebSocket endpoint: a thin front of the foxglove-sdk server.

Two things foxglove-sdk 0.30.3 (the newest release) does not do, done here for every client:

- **The protocol's old name.** The sdk accepts only the subprotocols ``foxglove.sdk.v1`` and
  ``foxglove.sdk.v1.1`` and refuses ``foxglove.websocket.v1`` with HTTP 400; the messages are
  the same (the name changed, the protocol did not), but every client built on the official
  ``@foxglove/ws-protocol`` package (0.8.0 offers only the old name) and the Foxglove and
  Lichtblick releases before the rename cannot connect. The front accepts the old and the new
  names and speaks to the sdk under the new one, every frame relayed unchanged both ways.
- **A subscription right after an advertisement.** The sdk queues a new channel's ``advertise``
  to a client before it enters the channel in that client's table (ConnectedClient's
  ``advertise_channels``: send, then insert); a client that answers at once, as Foxglove does,
  can be refused with ``Unknown channel ID: N`` and never gets the channel (the thread that
  creates the channel is the live view's low-priority one, so on a busy machine the window is
  wide). The front sees the refusal of a channel it saw advertised and subscribes it again
  (backing off, at most SUBSCRIBE_RETRIES times) instead of passing the error on.

The data frames cost one relay in this process's event loop thread; a slow client still slows
only itself: the relay reads the sdk's socket only as fast as it can write the client's, so the
sdk's per-client backlog (the oldest dropped) is what bounds it, as without the front.
"""
import asyncio
import json
import re
import threading

OLD_SUBPROTOCOL = 'foxglove.websocket.v1'
SDK_SUBPROTOCOLS = ('foxglove.sdk.v1', 'foxglove.sdk.v1.1')
SUBSCRIBE_RETRIES = 20
RETRY_FIRST_S = 0.005
RETRY_MAX_S = 0.5
_UNKNOWN_CHANNEL = re.compile(r'Unknown channel ID: (\d+)')
_STATUS_ERROR = 2   # the protocol's status levels: 0 info, 1 warning, 2 error


class FrontError(RuntimeError):
    """The front could not bind its address."""


class SubprotocolFront:
    """Serve ``host``:``port`` (0: any free port) and relay each client to ``upstream`` (the
    sdk server's ws:// URL). ``port`` is the bound port once constructed; ``retried`` counts
    the subscriptions sent again after an unknown-channel refusal."""

    def __init__(self, host, port, upstream):
        self.upstream = upstream
        self.port = None
        self.retried = 0
        self._error = None
        self._loop = None
        self._stop = None
        self._ready = threading.Event()
        self._thread = threading.Thread(target=lambda: asyncio.run(self._main(host, port)),
                                        name='live-front', daemon=True)
        self._thread.start()
        self._ready.wait(30.0)
        if self._error is not None or self.port is None:
            raise FrontError(self._error or 'the front did not start within 30 s')

    def close(self, timeout=5.0):
        if self._loop is not None and self._stop is not None:
            self._loop.call_soon_threadsafe(self._stop.set)
        self._thread.join(timeout)

    async def _main(self, host, port):
        from websockets.asyncio.server import serve
        self._loop = asyncio.get_running_loop()
        self._stop = asyncio.Event()
        try:
            # No compression and no keepalive pings: the sdk compresses nothing either, and a
            # starved (niced) process must not drop a client for a late pong.
            server = await serve(self._client, host, port, max_size=None, compression=None,
                                 ping_interval=None, select_subprotocol=_select,
                                 subprotocols=[*SDK_SUBPROTOCOLS, OLD_SUBPROTOCOL])
        except OSError as exc:
            self._error = str(exc)
            self._ready.set()
            return
        async with server:
            self.port = server.sockets[0].getsockname()[1]
            self._ready.set()
            await self._stop.wait()

    async def _client(self, ws):
        from websockets.asyncio.client import connect
        chosen = ws.subprotocol
        try:
            up = await connect(self.upstream, max_size=None, compression=None,
                               ping_interval=None, open_timeout=10.0,
                               subprotocols=[chosen if chosen in SDK_SUBPROTOCOLS
                                             else SDK_SUBPROTOCOLS[0]])
        except Exception as exc:  # noqa: BLE001 (refused, unreachable, timed out: all end the client)
            await ws.close(1011, f'live view upstream unavailable: {exc}'[:120])
            return
        state = _Subscriptions()
        tasks = [asyncio.create_task(self._to_server(ws, up, state)),
                 asyncio.create_task(self._to_client(up, ws, state))]
        try:
            await asyncio.wait(tasks, return_when=asyncio.FIRST_COMPLETED)
        finally:
            for task in tasks + state.retries:
                task.cancel()
            await up.close()
            await ws.close()

    async def _to_server(self, ws, up, state):
        async for frame in ws:
            if isinstance(frame, str):
                state.from_client(frame)
            await up.send(frame)

    async def _to_client(self, up, ws, state):
        async for frame in up:
            if isinstance(frame, str):
                sub = state.from_server(frame)
                if sub is not None:
                    self.retried += 1
                    state.retries.append(asyncio.create_task(self._resubscribe(up, state, sub)))
                    continue   # not the client's error: the channel is there, see below
            await ws.send(frame)

    async def _resubscribe(self, up, state, sub):
        await asyncio.sleep(state.delay(sub['channelId']))
        await up.send(json.dumps({'op': 'subscribe', 'subscriptions': [sub]}))


def _select(connection, offered):
    """The client's first offered name that the front speaks (the new names before the old one
    when a client offers both); a client offering none is refused (HTTP 400), as by the sdk."""
    from websockets.exceptions import NegotiationError
    for name in offered:
        if name in SDK_SUBPROTOCOLS:
            return name
    if OLD_SUBPROTOCOL in offered:
        return OLD_SUBPROTOCOL
    raise NegotiationError(f'no Foxglove WebSocket subprotocol offered: {", ".join(offered)}')


class _Subscriptions:
    """What one connection's control messages say: channels advertised, subscriptions asked
    for, and the retries of the refused ones."""

    def __init__(self):
        self.advertised = set()
        self.asked = {}       # channel id -> the client's subscription {id, channelId}
        self.tries = {}       # channel id -> retries so far
        self.retries = []     # pending retry tasks

    def from_client(self, text):
        msg = _json(text)
        if msg.get('op') == 'subscribe':
            for sub in msg.get('subscriptions', ()):
                self.asked[sub.get('channelId')] = sub
        elif msg.get('op') == 'unsubscribe':
            gone = set(msg.get('subscriptionIds', ()))
            for ch, sub in list(self.asked.items()):
                if sub.get('id') in gone:
                    del self.asked[ch]

    def from_server(self, text):
        """The subscription to send again if ``text`` refuses one of an advertised channel
        (and retries are left), else None."""
        msg = _json(text)
        op = msg.get('op')
        if op == 'advertise':
            self.advertised.update(c.get('id') for c in msg.get('channels', ()))
        elif op == 'unadvertise':
            self.advertised.difference_update(msg.get('channelIds', ()))
        elif op == 'status' and msg.get('level') == _STATUS_ERROR:
            m = _UNKNOWN_CHANNEL.search(str(msg.get('message', '')))
            if m:
                ch = int(m.group(1))
                if ch in self.advertised and ch in self.asked \
                        and self.tries.get(ch, 0) < SUBSCRIBE_RETRIES:
                    self.tries[ch] = self.tries.get(ch, 0) + 1
                    return self.asked[ch]
        return None

    def delay(self, channel_id):
        return min(RETRY_MAX_S, RETRY_FIRST_S * 2 ** (self.tries.get(channel_id, 1) - 1))


def _json(text):
    try:
        msg = json.loads(text)
    except ValueError:
        return {}
    return msg if isinstance(msg, dict) else {}
