"""CSV tables of ofv's outputs as dicts of numpy columns (what pandas.DataFrame takes)."""

import csv
import math

import numpy as np


def _is_int(text):
    try:
        int(text)
    except ValueError:
        return False
    return True


def _is_float(text):
    try:
        float(text)
    except ValueError:
        return False
    return True


def _column(values):
    """One column, typed as pandas types it: int64 when every field is an
    integer, float64 when every non-empty field is a number (empty: NaN),
    str otherwise. A column with no field at all is float64."""
    present = [v for v in values if v != ""]
    if len(present) == len(values) and present and all(_is_int(v) for v in present):
        return np.array([int(v) for v in values], dtype=np.int64)
    if all(_is_float(v) for v in present):
        return np.array([float(v) if v != "" else math.nan for v in values], dtype=np.float64)
    return np.array(values, dtype=str)


def read_csv_columns(path):
    """Reads a CSV file with a header line into {column name: numpy array},
    in the header's order (quoted fields as the csv module reads them)."""
    with open(path, newline="", encoding="utf-8") as f:
        reader = csv.reader(f)
        try:
            header = next(reader)
        except StopIteration:
            raise ValueError(f"{path}: empty file, expected a header line") from None
        rows = list(reader)
    for k, row in enumerate(rows):
        if len(row) != len(header):
            raise ValueError(f"{path}: line {k + 2} has {len(row)} fields, the header {len(header)}")
    return {name: _column([row[i] for row in rows]) for i, name in enumerate(header)}
