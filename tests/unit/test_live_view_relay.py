"""scripts/live_view_screenshot.py's relay: a client that offers only the protocol's old
subprotocol name reaches a server that accepts only the new one, every frame unchanged."""
import asyncio
import threading

import pytest

from live_view_screenshot import NEW_SUBPROTOCOL, OLD_SUBPROTOCOL, Relay


@pytest.mark.timeout(60)
def test_an_old_client_gets_the_new_servers_frames_unchanged_both_ways():
    from websockets.asyncio.client import connect
    from websockets.asyncio.server import serve
    from websockets.exceptions import InvalidStatus

    seen = {}
    ready, stop = threading.Event(), threading.Event()

    async def upstream(ws):
        seen['subprotocol'] = ws.subprotocol
        await ws.send('{"op": "serverInfo"}')
        await ws.send(bytes([1, 2, 3, 255]))
        seen['from_client'] = await ws.recv()

    async def server_main():
        async with serve(upstream, '127.0.0.1', 0, subprotocols=[NEW_SUBPROTOCOL]) as server:
            seen['port'] = server.sockets[0].getsockname()[1]
            ready.set()
            while not stop.is_set():
                await asyncio.sleep(0.05)
    thread = threading.Thread(target=lambda: asyncio.run(server_main()), daemon=True)
    thread.start()
    assert ready.wait(10)
    relay = Relay(f'ws://127.0.0.1:{seen["port"]}')

    async def old_client():
        with pytest.raises(InvalidStatus):   # the server alone refuses the old name
            await connect(f'ws://127.0.0.1:{seen["port"]}', subprotocols=[OLD_SUBPROTOCOL])
        async with connect(f'ws://127.0.0.1:{relay.port}', subprotocols=[OLD_SUBPROTOCOL]) as ws:
            got = [await ws.recv(), await ws.recv()]
            await ws.send('{"op": "subscribe"}')
            await asyncio.sleep(0.5)
            return ws.subprotocol, got
    try:
        subprotocol, got = asyncio.run(old_client())
    finally:
        relay.close()
        stop.set()
        thread.join(10)
    assert subprotocol == OLD_SUBPROTOCOL and seen['subprotocol'] == NEW_SUBPROTOCOL
    assert got == ['{"op": "serverInfo"}', bytes([1, 2, 3, 255])]
    assert seen['from_client'] == '{"op": "subscribe"}'
    assert relay.frames == 2
