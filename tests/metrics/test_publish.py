"""metrics.publish: a comparison's tables and their record, copied whole; a record whose code
has changed since is told apart."""

import json
from dataclasses import replace

import pytest

from envelope.provenance import code_fingerprint
from metrics.publish import main, publish, read_record, record_of, stale_code


def _compare_out(folder):
    folder.mkdir()
    (folder / "table2_errors.csv").write_text("# produced by x\nfamily,wwr_ape_mean\nall,1.25\n")
    (folder / "table2_errors.md").write_text("| all | 1.25 |\n")
    (folder / "timing.csv").write_text("scene,wall_time_s\na,3.2\n")
    (folder / "plot.png").write_bytes(b"png")
    (folder / "provenance.json").write_text(json.dumps({
        "produced_by": "python -m metrics.compare", "code_version": "abc123",
        "created_utc": "2026-11-28T23:00:00Z", "data": "/somewhere/tiny",
        "runs": [{"provenance": {"code": {"baselines": code_fingerprint("baselines")}}},
                 {"provenance": None}]}))
    return folder


def test_publish_copies_the_tables_and_writes_the_record(tmp_path):
    out = _compare_out(tmp_path / "out")
    written = publish(out, tmp_path / "tables" / "default")
    assert [p.name for p in written] == ["RECORD.json", "table2_errors.csv", "table2_errors.md"]
    record = read_record(tmp_path / "tables" / "default")
    assert record == record_of(out)
    assert (record.produced_by, record.code_version, record.data) == (
        "python -m metrics.compare", "abc123", "tiny")
    assert set(record.code) == {"baselines", "metrics"}
    assert stale_code(record) == {}
    old = replace(record, code={**record.code, "baselines": "0" * 16})
    assert stale_code(old) == {"baselines": ("0" * 16, code_fingerprint("baselines"))}


def test_bad_input_is_one_line(tmp_path, capsys):
    (tmp_path / "empty").mkdir()
    assert main(["--from", str(tmp_path / "empty"), "--name", "x",
                 "--root", str(tmp_path)]) == 2
    assert "has no provenance.json" in capsys.readouterr().err
    with pytest.raises(ValueError, match="no readable RECORD.json"):
        read_record(tmp_path / "empty")
