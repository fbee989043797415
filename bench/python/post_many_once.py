#!/usr/bin/env python3
"""One `Board.post_many` over a stream file, for counting its instructions:

    valgrind --tool=callgrind --toggle-collect='*post_many*' \\
        /root/.pyenv/versions/3.11.7/bin/python3.11 bench/python/post_many_once.py /tmp/s20k.events

(the interpreter's own binary, not pyenv's shim, which valgrind would follow
instead). The stream is `situ bench --stream-out`'s; the board is the one of
`vs_clipspy.py` (missions, sleeping agents' events taken)."""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import situ  # noqa: E402
from vs_clipspy import read_stream, situ_events  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
program = situ.load_path(ROOT / "rules" / "outdoor.situ")
events = situ_events(program, read_stream(Path(sys.argv[1])))
batch = situ.Board(program, missions=True, sleeping="take").post_many(events)
print(f"{len(events)} events, {len(batch.changes)} changes")
