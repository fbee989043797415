"""check, fmt, build and load, as a user of the package calls them."""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest

import situ

BAD = """states { A initial B }
agent X sensor { event E }
rule r { when state == A and F then B }
"""


def test_check_returns_findings_with_code_place_help_and_witness(tmp_path: Path) -> None:
    f = tmp_path / "bad.situ"
    f.write_text(BAD)
    for findings in (situ.check(f), situ.check(str(f)), situ.check(BAD, name="bad.situ")):
        [e] = [x for x in findings if x.severity == "error"]
        assert (e.code, e.line, e.column) == ("E0104", 3, 30)
        assert e.message == "undefined event `F`"
        assert e.help is not None and "`E`" in e.help
        assert e.file.endswith("bad.situ")


def test_check_of_clean_rules_is_empty(picker_text: str) -> None:
    assert [f for f in situ.check(picker_text) if f.severity == "error"] == []


def test_a_missing_file_is_a_read_error(tmp_path: Path) -> None:
    with pytest.raises(situ.ReadError) as e:
        situ.check(tmp_path / "nowhere.situ")
    assert e.value.code == "read"


def test_fmt_lays_out_and_refuses_syntax_errors_with_their_places() -> None:
    assert situ.fmt("states {A initial B}\n") == "states {\n    A initial\n    B\n}\n"
    with pytest.raises(situ.SituSyntaxError) as e:
        situ.fmt("states { A initial \n rule {")
    assert e.value.code.startswith("E0")
    assert e.value.findings and e.value.findings[0].line >= 1


def test_build_gives_bytes_and_their_sha256_and_saves_atomically(picker_text: str, tmp_path: Path) -> None:
    b = situ.build(picker_text)
    assert b.sha256 == hashlib.sha256(b.data).hexdigest()
    assert b.signed_by is None
    out = tmp_path / "picker.bundle"
    b.save(str(out))
    assert out.read_bytes() == b.data
    assert [p.name for p in tmp_path.iterdir()] == ["picker.bundle"], "no partial file is left"
    assert situ.load(b).states == situ.load(out.read_bytes()).states


def test_build_refuses_rules_with_errors_with_the_findings() -> None:
    with pytest.raises(situ.FindingsError) as e:
        situ.build(BAD)
    assert e.value.code == "E0104"
    assert [f.code for f in e.value.findings] == ["E0104"]


def test_a_signed_bundle_loads_under_its_key_and_an_unsigned_one_does_not(
    picker_text: str, keypair: tuple[Path, Path]
) -> None:
    secret, public = keypair
    signed = situ.build(picker_text, key=secret, binary=True)
    assert signed.signed_by
    assert situ.load(signed, trust=[public]).signed_by == signed.signed_by
    with pytest.raises(situ.TrustError):
        situ.load(situ.build(picker_text), trust=[public])
    with pytest.raises(situ.TrustError):
        situ.load(signed, trust=[])


def test_a_damaged_bundle_is_refused_under_any_policy(picker_text: str, keypair: tuple[Path, Path]) -> None:
    data = bytearray(situ.build(picker_text, binary=True).data)
    data[len(data) // 2] ^= 0xFF
    with pytest.raises(situ.BundleError):
        situ.load(bytes(data))
    with pytest.raises(situ.BundleError):
        situ.load(b"not a bundle")


def test_a_source_is_refused_where_only_signed_bundles_are_trusted(keypair: tuple[Path, Path]) -> None:
    from conftest import PICKER

    with pytest.raises(situ.TrustError):
        situ.load_path(PICKER, trust=[keypair[1]])


def test_a_program_describes_its_rules(picker: situ.Program) -> None:
    assert picker.initial == "IDLE"
    assert "Battery.BATT" in picker.events
    assert picker.fields("OBST") == [("distance", "f64"), ("side", "{left, right}")]
    assert "too_close" in picker.rules
