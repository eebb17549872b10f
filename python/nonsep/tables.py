"""CSV files of a nonsep run as numpy structured arrays, one field per column, named by the header.

Column types are decided by the column's name, never by its position, so that files with more, fewer or
reordered columns load alike:
  - integers (int64): trajectory, step, steps, basic_steps, grad_T, grad_V, crossing, poincare_crossings, and
    frequency_spectra.csv's signal and term (never empty in nonsep's files);
  - text (fixed-width str): status, stop_variable, message, integrator, scheme, order, error_estimate;
  - booleans: symplectic, separated ("true" / "false"; an empty cell is false);
  - every other column is a float64 column, where an empty cell is NaN; a column of another name that holds
    something that is not a number (a file this module does not know) is read as text.
Files are read by numpy's C reader (np.loadtxt, with RFC 4180 quotes), and numbers are converted by numpy, which
rounds correctly: every value is the double that Python's float() gives for the same text, so the shortest
round-trip decimals the host writes come back bit for bit.
"""
import csv
import io

import numpy as np

INTEGER_COLUMNS = frozenset({"trajectory", "step", "steps", "basic_steps", "grad_T", "grad_V", "crossing",
                             "poincare_crossings", "signal", "term"})
TEXT_COLUMNS = frozenset({"status", "stop_variable", "message", "integrator", "scheme", "order", "error_estimate"})
BOOLEAN_COLUMNS = frozenset({"symplectic", "separated"})


def read_table(path):
    """The CSV file at `path` (a header line, then rows) as a structured array with one row per line.

    A file of numbers without empty or quoted cells is parsed by np.loadtxt straight into its typed columns (1.2 to
    2.7 s of CPU for 10^6 rows of 7 columns on a loaded machine, the scan included). Any other file is read by
    np.loadtxt as cells of text (quoted cells included), and each column is then converted to its type at once
    (8.3 s of CPU for 10^6 rows of the 14 columns of trajectories.csv on a loaded machine).
    A last line without its newline is not a row: the host writes whole rows only, so such a line is what a hard
    kill (SIGKILL, a crash, a full disk) cut off, and it is dropped (docs/outputs.md, "Reading it after a hard kill").
    Raises ValueError when a row has a different number of cells than the header, or a cell cannot be read as
    its column's type.
    """
    with open(path, "rb") as f:
        names = next(csv.reader([f.readline().decode()]))
        has_rows, quoted, empty_cells, complete = _scan(f)
    if not has_rows:
        return np.empty(0, dtype=_dtype(names, {}))
    numbers_only = not quoted and not (TEXT_COLUMNS | BOOLEAN_COLUMNS).intersection(names)
    if numbers_only and not empty_cells and complete:
        try:
            return np.loadtxt(path, delimiter=",", skiprows=1, dtype=_dtype(names, {}), ndmin=1)
        except ValueError:
            pass  # a column this module does not know holds text: read it as cells below
    with open(path, newline="") as f:
        body = f.read().partition("\n")[2]
    if not complete:
        body = body[: body.rfind("\n") + 1]
        if not body.strip():
            return np.empty(0, dtype=_dtype(names, {}))
    return _read_text(names, body)


def _scan(f, chunk_size=1 << 24):
    """(any row, any '"', any empty cell, ends in a newline) for the rest of binary file `f`, read in chunks of
    16 MiB."""
    has_rows = quoted = empty_cells = False
    previous = b"\n"  # the header's newline: a row starting with "," starts with an empty cell
    while chunk := f.read(chunk_size):
        has_rows = has_rows or bool(chunk.strip())
        text = previous + chunk
        quoted = quoted or b'"' in chunk
        empty_cells = empty_cells or b",," in text or b",\n" in text or b"\n," in text
        previous = chunk[-1:]
    empty_cells = empty_cells or previous == b","
    return has_rows, quoted, empty_cells, previous == b"\n"


def table_from_columns(names, columns):
    """A structured array from `columns` (one sequence of cells per name), typed by name as read_table types a file's
    columns. A column's cells are all strings (a file's text; "" is an empty cell), or all numbers and None (empty)
    for a numeric column; text columns are strings."""
    text_columns = {}
    converted = []
    for name, cells in zip(names, columns):
        kind = _kind(name)
        text = len(cells) > 0 and isinstance(cells[0], str)
        cells = np.asarray(cells, dtype=object).reshape(-1)
        if kind == "float":
            try:
                converted.append(_floats(cells) if text else cells.astype(np.float64))
                continue
            except ValueError:
                kind = "text"
        if kind == "text":
            cells = cells.astype(str)
            text_columns[name] = int(np.char.str_len(cells).max(initial=1))
            converted.append(cells)
        elif kind == "integer":
            converted.append(_integers(name, cells))
        else:
            converted.append(cells == "true")
    table = np.empty(len(converted[0]) if converted else 0, dtype=_dtype(names, text_columns))
    for name, values in zip(names, converted):
        table[name] = values
    return table


def _kind(name):
    if name in INTEGER_COLUMNS:
        return "integer"
    if name in TEXT_COLUMNS:
        return "text"
    if name in BOOLEAN_COLUMNS:
        return "boolean"
    return "float"


def _dtype(names, text_widths):
    fields = []
    for name in names:
        kind = _kind(name)
        if name in text_widths:
            fields.append((name, f"U{max(text_widths[name], 1)}"))
        elif kind == "integer":
            fields.append((name, np.int64))
        elif kind == "text":
            fields.append((name, "U1"))
        elif kind == "boolean":
            fields.append((name, bool))
        else:
            fields.append((name, np.float64))
    return np.dtype(fields)


def _floats(cells):
    # An array of cell texts: "" is NaN, every other cell is converted by numpy (with float(), correctly rounded);
    # a cell that is not a number raises ValueError.
    values = np.full(len(cells), np.nan)
    filled = cells != ""
    values[filled] = cells[filled].astype(np.float64)
    return values


def _integers(name, cells):
    try:
        return cells.astype(np.int64)
    except ValueError as error:
        raise ValueError(f"column {name}: found a cell that is not an integer ({error})") from None


def _read_text(names, body):
    # numpy's reader splits the rows into cells, one str object each (quotes as in RFC 4180; '#' is text, not a
    # comment); a file whose rows differ in length from each other or from the header is read again by the csv
    # module, which names the line.
    try:
        cells = np.loadtxt(io.StringIO(body), delimiter=",", quotechar='"', comments=None, dtype=object, ndmin=2)
    except ValueError:
        cells = None
    if cells is None or cells.shape[1] != len(names):
        return _read_cells(names, body)
    return table_from_columns(names, cells.T)


def _read_cells(names, body):
    rows = [row for row in csv.reader(io.StringIO(body)) if row]
    for number, row in enumerate(rows, start=2):
        if len(row) != len(names):
            raise ValueError(f"line {number}: found {len(row)} cells; expected {len(names)}, as in the header")
    columns = list(zip(*rows)) if rows else [() for _ in names]
    return table_from_columns(names, columns)
