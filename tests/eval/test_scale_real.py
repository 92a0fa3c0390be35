"""``meshvis bench scale --real``'s record and table: CPU seconds next to the wall seconds."""

import json

from meshvis.eval.bench.scale_real import format, record


def test_record_writes_the_cpu_seconds_and_the_table_shows_them(tmp_path):
    out = tmp_path / "stage.json"
    sum(i * i for i in range(200_000))  # some CPU time of this process
    record(0, 1.0, str(out))
    row = json.loads(out.read_text())
    assert row["cpu_seconds"] > 0 and row["status"] == 0
    row.update(faces=1000, command="orient", seconds=2.5, load_average=0.5, cpu_seconds=12.5)
    table = format([row])
    assert "cpu s" in table.splitlines()[0]
    assert table.splitlines()[1].split()[2:4] == ["2.5", "12.5"]  # seconds, then CPU seconds
