"""A text input read in blocks on pyarrow's threads (:func:`washbench.io.tables._threaded_read`) gives the table and
line numbers of the one-block read on one thread, which a line that is not a data row still goes to."""

from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.csv as pacsv
import pytest

from washbench.io import tables

ROWS = 30_000  # about 3 MB of text in the mixed file: several of pyarrow's 1 MB blocks


def _one_block(path: Path, string_columns: set[str], decimal: str = ".") -> tables.SourceTable:
    """The read as it was before the threaded one: one block, one thread (``_threaded_read`` declines)."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(tables, "_threaded_read", lambda *args: None)
        return tables.read_text_table(path, None, string_columns, decimal)


def _same(a: tables.SourceTable, b: tables.SourceTable) -> None:
    assert a.table.schema == b.table.schema
    for name in a.table.column_names:
        x, y = a.table.column(name).combine_chunks(), b.table.column(name).combine_chunks()
        assert x.equals(y), name
        if pa.types.is_floating(x.type):  # equal as values and as bits (no other rounding of the text)
            assert x.to_numpy(zero_copy_only=False).tobytes() == y.to_numpy(zero_copy_only=False).tobytes(), name
    assert np.array_equal(a.lines, b.lines)


def _columns(rng: np.random.Generator) -> dict[str, list[str]]:
    """Columns whose type the first block alone would get wrong: integers then a decimal, empty then numbers,
    numbers then text, and plain decimals of every magnitude."""
    t = np.arange(ROWS) / 120.0
    ints = [str(i) for i in rng.integers(-5000, 5000, ROWS)]
    ints[-3] = "2.5"  # a decimal in the last block only
    empty_first = [""] * (ROWS // 2) + [repr(float(v)) for v in rng.normal(size=ROWS - ROWS // 2)]
    text_last = [repr(float(v)) for v in rng.normal(size=ROWS)]
    text_last[-7] = "n/a"
    return {
        "t_s": [repr(float(v)) for v in t],
        "f_x_mps2": [repr(float(v)) for v in rng.normal(scale=10.0 ** rng.integers(-8, 8), size=ROWS)],
        "count": ints,
        "late": empty_first,
        "note": text_last,
        "flag": ["true" if v else "false" for v in rng.integers(0, 2, ROWS)],
    }


@pytest.mark.parametrize("suffix", [".csv", ".tsv.gz"])
def test_a_read_in_blocks_on_threads_gives_the_one_block_table(tmp_path: Path, suffix: str) -> None:
    cols = _columns(np.random.default_rng(7))
    delim = "\t" if suffix.startswith(".tsv") else ","
    text = "\n".join([delim.join(cols), *(delim.join(r) for r in zip(*cols.values(), strict=True))]) + "\n"
    path = tmp_path / f"log{suffix}"
    path.write_bytes(gzip.compress(text.encode()) if suffix.endswith(".gz") else text.encode())
    fast = tables.read_text_table(path, None, {"t_s"})
    assert fast.table.column("count").num_chunks > 1  # read in blocks: the case the claim is about
    assert fast.table.schema.field("count").type == pa.float64()  # promoted as the whole file reads
    assert fast.table.schema.field("late").type == pa.float64()
    assert fast.table.schema.field("note").type == pa.string()
    _same(fast, _one_block(path, {"t_s"}))


def test_a_line_that_is_no_data_row_goes_to_the_one_block_read_with_its_line_numbers(tmp_path: Path) -> None:
    rows = [f"{i / 120.0!r},{np.sin(i)!r}" for i in range(2 * ROWS)]  # 2.4 MB
    rows.insert(50_000, "# a comment inside the data")
    path = tmp_path / "log.csv"
    path.write_text("# made by hand\nt_s,f_x_mps2\n" + "\n".join(rows) + "\n")
    assert tables._threaded_read(path, 2, ["t_s", "f_x_mps2"], ",", _convert()) is None
    read = tables.read_text_table(path, None, set())
    assert read.table.num_rows == 2 * ROWS
    assert read.lines[0] == 3 and read.lines[49_999] == 50_002 and read.lines[50_000] == 50_004  # the comment skipped
    path.write_text("t_s,f_x_mps2\n" + "\n".join(rows[:1000]) + "\n\n" + "\n".join(rows[1001:]) + "\n")
    read = tables.read_text_table(path, None, set())  # an empty line: a row of nulls on its line, as read whole
    assert read.table.column("t_s").null_count == 1 and read.lines[1000] == 1002
    _same(read, _one_block(path, set()))
    rows[1500] += ",7.0"
    path.write_text("t_s,f_x_mps2\n" + "\n".join(rows) + "\n")
    with pytest.raises(tables.WashbenchError, match=r"log\.csv:1502: wrong number of fields \(expected 2"):
        tables.read_text_table(path, None, set())


def _convert() -> pacsv.ConvertOptions:
    return pacsv.ConvertOptions(null_values=[""], strings_can_be_null=True)
