#!/usr/bin/env python3
"""A TCP relay that delays: the fault tests' stand-in for netem, which this
machine's kernel lacks.

    python3 relay.py --listen 10.20.0.254 --delay-ms 50 20000=10.20.0.1:7447 udp:21000=10.20.0.1:7460 …

Each `PORT=HOST:TPORT` listens on `--listen`:PORT; every connection made
there is joined to a new connection to HOST:TPORT, and every chunk read from
either side is written to the other `--delay-ms` later (plus up to
`--jitter-ms` at random, the order of the stream kept: a chunk never
overtakes the one before it). A side that closes closes the other once what
it sent has been passed on. Each `udp:PORT=HOST:TPORT` receives datagrams
on `--listen`:PORT and sends each to HOST:TPORT `--delay-ms` later (plus
the jitter; one way only, as the boards' beats go). It prints `listening`
when every port listens, and one line per connection.
"""

import argparse
import asyncio
import random
import socket
import sys
import time


def nodelay(writer: asyncio.StreamWriter) -> None:
    sock = writer.get_extra_info("socket")
    if sock is not None:
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)


async def pump(reader: asyncio.StreamReader, writer: asyncio.StreamWriter, delay: float, jitter: float) -> None:
    """Reads chunks and writes each `delay` (+ jitter) after it came, in order."""
    queue: asyncio.Queue = asyncio.Queue()
    loop = asyncio.get_running_loop()

    async def write() -> None:
        while True:
            due, chunk = await queue.get()
            wait = due - loop.time()
            if wait > 0:
                await asyncio.sleep(wait)
            if chunk is None:
                break
            writer.write(chunk)
            await writer.drain()

    writing = asyncio.create_task(write())
    last_due = 0.0
    try:
        while True:
            chunk = await reader.read(65536)
            due = max(last_due, loop.time() + delay + random.uniform(0.0, jitter))
            last_due = due
            await queue.put((due, chunk if chunk else None))
            if not chunk:
                break
        await writing
    except (ConnectionError, OSError):
        writing.cancel()
    finally:
        try:
            writer.close()
        except (ConnectionError, OSError):
            pass


async def serve(listen: str, port: int, host: str, tport: int, delay: float, jitter: float) -> asyncio.AbstractServer:
    async def handle(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        try:
            treader, twriter = await asyncio.open_connection(host, tport)
        except OSError as e:
            print(f"{time.time_ns()} {port}: cannot reach {host}:{tport}: {e}", flush=True)
            writer.close()
            return
        nodelay(writer)
        nodelay(twriter)
        print(f"{time.time_ns()} {port}: {writer.get_extra_info('peername')} -> {host}:{tport}", flush=True)
        await asyncio.gather(pump(reader, twriter, delay, jitter), pump(treader, writer, delay, jitter))

    return await asyncio.start_server(handle, listen, port)


class Datagrams(asyncio.DatagramProtocol):
    """Passes each datagram on to `target`, `delay` (+ jitter) later."""

    def __init__(self, target: tuple, delay: float, jitter: float) -> None:
        self.target, self.delay, self.jitter = target, delay, jitter
        self.transport = None

    def connection_made(self, transport) -> None:
        self.transport = transport

    def datagram_received(self, data: bytes, addr) -> None:
        loop = asyncio.get_running_loop()
        loop.call_later(self.delay + random.uniform(0.0, self.jitter), self.send, data)

    def send(self, data: bytes) -> None:
        try:
            self.transport.sendto(data, self.target)
        except OSError:
            pass

    def error_received(self, exc) -> None:
        pass


async def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--listen", required=True)
    ap.add_argument("--delay-ms", type=float, default=0.0)
    ap.add_argument("--jitter-ms", type=float, default=0.0)
    ap.add_argument("routes", nargs="+", help="PORT=HOST:TPORT")
    args = ap.parse_args()
    servers = []
    loop = asyncio.get_running_loop()
    for route in args.routes:
        port, target = route.split("=", 1)
        host, tport = target.rsplit(":", 1)
        if port.startswith("udp:"):
            await loop.create_datagram_endpoint(
                lambda: Datagrams((host, int(tport)), args.delay_ms / 1000, args.jitter_ms / 1000),
                local_addr=(args.listen, int(port[4:])),
            )
            continue
        servers.append(
            await serve(args.listen, int(port), host, int(tport), args.delay_ms / 1000, args.jitter_ms / 1000)
        )
    print("listening", flush=True)
    await asyncio.gather(*(s.serve_forever() for s in servers))
    return 0


if __name__ == "__main__":
    sys.exit(asyncio.run(main()))
