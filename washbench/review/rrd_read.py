"""Reading .rrd files back with ``rerun.chunk.RrdReader`` (pyarrow only, no viewer): traces, text, properties.

Used by the tests (including the pipeline's end-to-end test) and by ``washbench replay`` to compare recordings.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

__all__ = [
    "read_blueprint_components",
    "read_component",
    "read_properties",
    "read_scalar_series",
    "read_static",
    "read_text_documents",
]

TIMELINE = "time"


def _time_seconds(col: pa.Array) -> np.ndarray:
    ns = np.asarray(col.cast(pa.int64()).to_numpy(zero_copy_only=False), dtype=np.int64)
    return ns * 1e-9


def _component_values(col: pa.Array) -> np.ndarray:
    """A component column (a list of instances per row) -> array (rows, [instances,] *shape).

    The instance axis is dropped when every row holds one instance; rows of unequal length give an object array.
    """
    lengths = pc.list_value_length(col)
    if col.null_count == 0 and len(col) > 0 and pc.min_max(lengths).as_py()["min"] == pc.max(lengths).as_py():
        per_row = int(lengths[0].as_py())
        inner = col.flatten()
        shape = [len(col)] if per_row == 1 else [len(col), per_row]
        while pa.types.is_fixed_size_list(inner.type):
            shape.append(inner.type.list_size)
            inner = inner.flatten()
        return np.asarray(inner.to_numpy(zero_copy_only=False)).reshape(shape)
    return np.array(col.to_pylist(), dtype=object)


def read_component(path: Path, component: str) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Every entity's time-indexed values of ``component`` (e.g. "Scalars:scalars", "Transform3D:quaternion").

    Returns entity path -> (t_s (M,), values), sorted by time. When each row holds one instance, ``values`` has shape
    (M,) for scalars and (M, k) for k-vectors; with L > 1 instances in every row, (M, L) and (M, L, k). Values keep
    the dtype rerun stores (scalars float64, vectors and quaternions float32); rows of unequal length give an object
    array of per-row lists. Static data is ignored.
    """
    from rerun.chunk import RrdReader

    parts: dict[str, list[tuple[np.ndarray, np.ndarray]]] = {}
    for chunk in RrdReader(str(path)).stream():
        if chunk.is_static or TIMELINE not in chunk.timeline_names:
            continue
        batch = chunk.to_record_batch()
        if component not in batch.schema.names:
            continue
        t = _time_seconds(batch.column(TIMELINE))
        parts.setdefault(chunk.entity_path, []).append((t, _component_values(batch.column(component))))
    out: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for entity, pieces in parts.items():
        t = np.concatenate([p[0] for p in pieces])
        v = np.concatenate([p[1] for p in pieces])
        order = np.argsort(t, kind="stable")
        out[entity] = (t[order], v[order])
    return out


def read_scalar_series(path: Path) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Every scalar series in the .rrd file: entity path -> (t_s (M,), values float64).

    ``values`` is (M,) for an entity with one line and (M, L) for L lines (e.g. the perceived motion of every source).
    """
    return read_component(path, "Scalars:scalars")


def read_static(path: Path, component: str) -> dict[str, list[object]]:
    """Every static value of ``component`` (e.g. "SeriesLines:names"): entity path -> list of instances."""
    from rerun.chunk import RrdReader

    out: dict[str, list[object]] = {}
    for chunk in RrdReader(str(path)).stream():
        if not chunk.is_static:
            continue
        batch = chunk.to_record_batch()
        if component in batch.schema.names:
            for row in batch.column(component).to_pylist():
                if row is not None:
                    out[chunk.entity_path] = list(row)
    return out


def read_text_documents(path: Path) -> dict[str, str]:
    """Every static text document in the .rrd file: entity path -> text."""
    return {k: v[0] for k, v in read_static(path, "TextDocument:text").items() if v}


def read_properties(path: Path) -> dict[str, str]:
    """The provenance strings written as the recording property ``provenance`` (empty if there are none)."""
    from rerun.chunk import RrdReader

    out: dict[str, str] = {}
    for chunk in RrdReader(str(path)).stream():
        if not chunk.entity_path.startswith("/__properties/provenance"):
            continue
        batch = chunk.to_record_batch()
        for name in batch.schema.names:
            if name.startswith("rerun.controls."):
                continue
            values = batch.column(name).to_pylist()
            if values and values[-1]:
                out[name.split(":", 1)[-1]] = str(values[-1][0])
    return out


def read_blueprint_components(path: Path) -> dict[str, dict[str, list[object]]]:
    """The stored blueprint: entity path -> {component: its last value (a list of instances)}."""
    from rerun.chunk import RrdReader

    reader = RrdReader(str(path))
    out: dict[str, dict[str, list[object]]] = {}
    for blueprint in reader.blueprints():
        for chunk in reader.stream(store=blueprint):
            batch = chunk.to_record_batch()
            for name in batch.schema.names:
                if ":" in name:
                    rows = [r for r in batch.column(name).to_pylist() if r is not None]
                    if rows:
                        out.setdefault(chunk.entity_path, {})[name] = (
                            rows[-1] if isinstance(rows[-1], list) else [rows[-1]]
                        )
    return out
