"""armscope.batch and armscope.size: the commands' results as the JSON they write, parsed — the same
as the command line's, a failed experiment in the summary rather than raised."""
import json
import subprocess

import pytest

import armscope

MANIFEST = """name = "small"
[defaults]
duration = 0.3
[[experiment]]
name = "wave-{amp-deg}"
grid = { amp-deg = [10, 20] }
[[experiment]]
name = "broken"
kp = [1, 2, 3]
"""


def without_wall_time(doc):
    for e in doc["experiments"]:
        e.pop("wall_time", None)
        if e.get("summary"):
            e["summary"].pop("wall_time", None)
    doc.pop("manifest", None)
    return doc


def test_batch_gives_the_commands_summary_with_its_failure(tmp_path):
    manifest = tmp_path / "small.toml"
    manifest.write_text(MANIFEST)
    ours = armscope.batch(manifest, jobs=2, no_compare=True)
    cli = subprocess.run(["armscope", "batch", str(manifest), "--out", str(tmp_path / "cli"), "--jobs", "2", "--no-compare"], capture_output=True, text=True)
    assert cli.returncode == 1, cli.stderr  # a failed experiment: the command exits 1
    expected = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert without_wall_time(ours) == without_wall_time(expected)
    assert [e["status"] for e in ours["experiments"]] == ["completed", "completed", "failed"]
    assert "--kp" in ours["experiments"][2]["error"]


def test_size_gives_the_commands_size_json(tmp_path):
    ours = armscope.size(payload=0.2)
    cli = subprocess.run(["armscope", "size", "--payload", "0.2", "--out", str(tmp_path)], capture_output=True, text=True)
    assert cli.returncode == 0, cli.stderr
    expected = json.loads((tmp_path / "size.json").read_text())
    assert ours["joints"] == expected["joints"] and ours["payload_kg"] == 0.2
    with pytest.raises(armscope.ArmscopeError, match="size: unexpected argument '--bogus"):
        armscope.size(bogus=1)
