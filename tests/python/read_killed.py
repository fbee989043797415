#!/usr/bin/env python3
"""Reads a recording whose run was killed (`situ run --record F.mcap`, then
SIGKILL) with the standard reader of the `mcap` package from PyPI
(`make_reader`, what Foxglove's tooling uses), and prints one line:

    messages N /situ/events E bundle yes|no

Exit 0 when the reader read at least one message; 1 otherwise, or when the
reader fails (an exception is a failure: a killed run must still leave a
file the standard reader reads). A missing package is an error (exit 2),
never a skip: install examples/python/requirements.txt.

Usage: read_killed.py RECORDING.mcap
"""
import sys

try:
    from mcap.reader import make_reader
except ImportError as e:  # the test that runs this fails, it does not skip
    print(f"read_killed.py: the mcap package is missing ({e}): "
          "pip install -r examples/python/requirements.txt", file=sys.stderr)
    sys.exit(2)


def main(path):
    total = 0
    events = 0
    with open(path, "rb") as f:
        for _schema, channel, _message in make_reader(f).iter_messages():
            total += 1
            if channel.topic == "/situ/events":
                events += 1
        f.seek(0)
        bundle = any(a.name == "bundle.json" for a in make_reader(f).iter_attachments())
    print(f"messages {total} /situ/events {events} bundle {'yes' if bundle else 'no'}")
    return 0 if total > 0 else 1


if __name__ == "__main__":
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    sys.exit(main(sys.argv[1]))
