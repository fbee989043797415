"""The messages of ros2-map/tests/cdr_samples.py serialized by Eclipse Cyclone DDS
(the `cyclonedds` package) in XCDR1 and in XCDR2, both byte orders; with
`--appendable`, every type of them declared appendable first: XCDR2 is then
the delimited form (`00 08`/`00 09`) and `xcdr1_hex` is left out (Cyclone
DDS writes an appendable type in XCDR2 only; a run without the flag gives
the same messages' XCDR1).

Prints one JSON line per message and byte order:
{"name": ..., "type": "pkg/msg/Name", "xcdr1_hex": ..., "xcdr2_hex": ...}
Run by bridge-ros2/tests/xcdr2_cyclonedds.rs; exits 3 when cyclonedds is missing.
"""

import importlib.util
import json
import pathlib
import sys

HERE = pathlib.Path(__file__).resolve().parent
spec = importlib.util.spec_from_file_location("cdr_samples", HERE.parent.parent / "ros2-map" / "tests" / "cdr_samples.py")
samples = importlib.util.module_from_spec(spec)
spec.loader.exec_module(samples)  # exits 3 itself when cyclonedds is missing
from cyclonedds.idl import Endianness, IdlStruct  # noqa: E402
from cyclonedds.idl.annotations import appendable  # noqa: E402


def main():
    delimited = "--appendable" in sys.argv[1:]
    if delimited:
        for value in list(vars(samples).values()):
            if isinstance(value, type) and issubclass(value, IdlStruct) and value is not IdlStruct:
                appendable(value)
    for name, msg in samples.samples():
        for suffix, order in [("", Endianness.Little), ("_be", Endianness.Big)]:
            v1 = msg.serialize(endianness=order)
            v2 = msg.serialize(endianness=order, use_version_2=True)
            line = {"name": name + suffix, "type": samples.full_name(msg), "xcdr2_hex": v2.hex()}
            if not delimited:
                line["xcdr1_hex"] = v1.hex()
            print(json.dumps(line))


if __name__ == "__main__":
    main()
