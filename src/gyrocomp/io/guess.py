"""A table's layout guessed from its column names and the magnitudes of its first rows, for ``gyrocomp init``.

Names: a column is a gyro, accelerometer or temperature channel when one of its name's words says so (``gyr*``,
``omega``, ``rate``; ``acc*``; ``temp*``), its axis the last letter x, y or z; the time is the column named
``time``/``timestamp``/``stamp``/``t`` (else the first column that only increases). Units: a word of the name
(``us``, ``ms``, ``rad``, ``dps``, ``mg``, ``m_s2``) decides; else the magnitudes: the time unit whose sample
period lies within 0.1 ms..1 s, the accelerometer unit in which the norm at rest is near 1 (g, m/s2, mg), the gyro
in rad/s when the accelerometer is in m/s2 (a logger that writes SI writes it throughout), else deg/s. Each guess
comes with the reason, to be checked by the user: nothing here is certain.

Files of named arrays (HDF5/NetCDF, MAT-files, ``.npz``) are guessed the same way from their arrays' names: an
(n, 3) array whose name says gyro or accelerometer is that channel whole, one-dimensional arrays per axis, the time
and the temperature; the units from the names and the magnitudes of the first ``GUESS_ROWS`` samples.
"""

from __future__ import annotations

import csv
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.csv as pacsv
import pyarrow.parquet as pq

from ..errors import InputError
from .hdf5 import ArrayStore, sample_hdf5
from .matlab import load_arrays
from .readers import detect_format
from .serial import MAX_LINE_BYTES, looks_headerless, read_headerless, split_fields
from .columns import holds_clock, vector_column
from .tables import TableLayout, check_parquet_footer, detect_table_format
from .text_format import DECOMPRESS_ERRORS, DELIMITERS, TextFormat, csv_source, read_error

#: rows read to guess from
GUESS_ROWS = 20_000
_TIME_WORDS = {"time", "timestamp", "stamp", "t", "ts", "timeus", "timems", "sec", "seconds", "sampletimefine"}
#: words of a column that counts packets or samples: increasing, but no time unless nothing else is (its period is
#: not in the file)
_COUNTER_WORDS = {"counter", "packetcounter", "packet", "count", "seq", "sequence", "index", "idx", "frame", "n"}
_TIME_UNIT_WORDS = {
    "us": "us",
    "usec": "us",
    "micros": "us",
    "timeus": "us",
    "ms": "ms",
    "msec": "ms",
    "timems": "ms",
    "ns": "ns",
    "nsec": "ns",
    "sampletimefine": "100 us",  # Xsens (MT Manager, the SDK): ticks of a 10 kHz clock
}
#: sample periods a log plausibly has [s]: 10 kHz to 1 Hz
_PERIOD_RANGE_S = (1e-4, 1.0)
_TIME_FACTORS = (("s", 1.0), ("ms", 1e-3), ("us", 1e-6), ("ns", 1e-9))
_ACCEL_NORMS = (("g", 1.0), ("m/s2", 9.80665), ("mg", 1000.0))


@dataclass(frozen=True)
class LayoutGuess:
    """What :func:`guess_layout` found: the layout, why (one line per channel or unit), the columns left unused
    and the field separator of a text table (None for Parquet)."""

    path: str
    layout: TableLayout
    reasons: tuple[str, ...]
    unused: tuple[str, ...]


def _words(name: str) -> list[str]:
    return [w for w in re.split(r"[^a-z0-9]+", name.lower()) if w]


def _axis(name: str) -> str | None:
    """x, y or z: a word of its own (the last such), else the last letter of the channel's word (``GyrZ``, ``ax``)
    or of the name's last word."""
    words = _words(name)
    alone = [w for w in words if w in ("x", "y", "z")]
    if alone:
        return alone[-1]
    for word in reversed(words):
        if word.startswith(("gyr", "acc", "omega", "rate", "w", "a")) and len(word) > 1 and word[-1] in "xyz":
            return word[-1]
    return words[-1][-1] if words and len(words[-1]) > 1 and words[-1][-1] in "xyz" else None


#: a name of two letters, a channel's and an axis's (``gx``, ``wz``, ``ay``: an Arduino sketch's), its kind
_SHORT_KINDS = {"g": "gyro", "w": "gyro", "a": "accel"}


def _kind(name: str) -> str | None:
    words = _words(name)
    joined = "".join(words)
    if len(joined) == 2 and joined[0] in _SHORT_KINDS and joined[1] in "xyz":
        return _SHORT_KINDS[joined[0]]
    if any(w.startswith("temp") or w == "tmp" for w in words) or joined.startswith("temp"):
        return "temperature"
    if any(w.startswith("gyr") or w in ("omega", "rate", "angular", "gyro") for w in words):
        return "gyro"
    if any(w.startswith("acc") or w in ("lin", "acceleration") for w in words):
        return "accel"
    return None


class NoTimeColumn(InputError):
    """No column of the table looks like its time, and no rate was given."""


class HeaderlessTable(InputError):
    """The table has no header line (a serial terminal's log): its rows hold ``count`` numbers, like ``example``;
    the caller asks for their names."""

    def __init__(self, path: Path, count: int, example: str):
        super().__init__(
            f"{path}: a table without a header line, rows of {count} numbers (e.g. {example!r}); give "
            f"their names in order (names=gyro_x,gyro_y,gyro_z,temperature)"
        )
        self.count = count
        self.example = example


def _headerless_rows(head: bytes) -> tuple[int, str] | None:
    """(numbers per row, an example row) when most of the first lines of a text table are rows of numbers and
    none of them is a header of that many names; None when it has a header."""
    lines = [line.strip() for line in head.decode("utf-8", "replace").splitlines()[:-1] if line.strip()][:50]
    rows = [line for line in lines if looks_headerless(line)]
    if not rows or len(rows) <= len(lines) / 2:
        return None
    counts = [len(split_fields(row)) for row in rows]
    count = max(set(counts), key=counts.count)
    first = next(i for i, line in enumerate(lines) if len(split_fields(line)) == count and looks_headerless(line))
    # a header: the line just before the first row, as many fields as the row split the same way, none of them a
    # number (split as the rows are; or by one separator, as a CSV's quoted names with spaces are, "Time (s)",
    # "Gyroscope x (rad/s)", or a table of semicolons and decimal commas is: Zeit [s];Drehrate X, 0,01;0,25)
    before, row = (lines[first - 1] if first > 0 else ""), lines[first]
    splits = [(split_fields(before), count)]  # a separator that splits neither line is no evidence: n > 1
    splits += [
        (next(csv.reader([before], delimiter=d), []), len(next(csv.reader([row], delimiter=d), []))) for d in DELIMITERS
    ]
    splits = [(f, n) for k, (f, n) in enumerate(splits) if k == 0 or n > 1]
    if before and any(len(f) == n and not any(looks_headerless(x) for x in f) for f, n in splits):
        return None
    return count, lines[first][:MAX_LINE_BYTES]


def _sample(path: Path, fmt: str) -> tuple[pa.Table, str | None, list[str], tuple[str, ...] | None]:
    """The first rows, the field separator (None for Parquet), the preamble's lines (before the header) and the
    fields of a line of units under the header (None without one)."""
    if fmt == "parquet":
        check_parquet_footer(path)
        parquet = pq.ParquetFile(path)
        first = parquet.read_row_group(0) if parquet.num_row_groups else parquet.read()
        return first.slice(0, GUESS_ROWS), None, [], None
    source, head = csv_source(path)
    if not head.strip():
        raise InputError(f"{path}: the file is empty; nothing to guess from")
    headerless = _headerless_rows(head[:4096])
    if headerless is not None:
        raise HeaderlessTable(path, *headerless)
    text = TextFormat.found(head[:4096], TableLayout())
    batches, rows = [], 0
    try:
        reader = pacsv.open_csv(
            text.source(path, source),
            read_options=text.read_options(),
            parse_options=text.parse_options(),
            convert_options=pacsv.ConvertOptions(decimal_point=text.decimal),
        )
        for batch in reader:
            batches.append(batch)
            rows += batch.num_rows
            if rows >= GUESS_ROWS:
                break
    except DECOMPRESS_ERRORS as exc:
        raise read_error(path, exc, head) from None
    preamble = head.decode("utf-8", "replace").split("\n")[: text.preamble_lines]
    table = pa.Table.from_batches(batches, schema=reader.schema).slice(0, GUESS_ROWS)
    return table, text.delimiter, preamble, text.units


#: a preamble's line that states the sample rate: a key (Fs, rate, sample rate, update rate, ODR, frequency), a
#: separator, a number, an optional Hz (``Fs,100``, ``// Update Rate: 100.0Hz``)
_STATED_RATE = re.compile(
    r"^[\s/#;%*]*(?:fs|odr|freq(?:uency)?|(?:sample|sampling|update|output data|data)?[ _-]?rate)"
    r"(?:[ _-]?\[?hz\]?)?\s*[:=,;\t ]\s*([0-9]+(?:\.[0-9]+)?)\s*(?:hz)?\s*$",
    re.IGNORECASE,
)
#: the rates a stated rate may be [Hz]
_STATED_RATE_RANGE_HZ = (0.01, 100_000.0)


def _stated_rate(preamble: list[str]) -> tuple[float, str] | None:
    """(rate [Hz], the line) of the first preamble line that states a sample rate, within the plausible range."""
    for line in preamble:
        found = _STATED_RATE.match(line.strip())
        if found and _STATED_RATE_RANGE_HZ[0] <= float(found[1]) <= _STATED_RATE_RANGE_HZ[1]:
            return float(found[1]), line.strip()
    return None


def _numbers(table: pa.Table, column: str) -> np.ndarray | None:
    try:
        values = table.column(column).to_numpy(zero_copy_only=False).astype(float)
    except (pa.ArrowInvalid, TypeError, ValueError):
        return None
    return values[np.isfinite(values)]


#: why a unit was taken from a column's name (for a file of arrays the name carries the array's units attribute,
#: and the reason says that instead: _guess_arrays)
_NAMED_SO = "the column's name says so"


def _with_units(
    table: pa.Table, columns: dict[str, str], units: tuple[str, ...] | None
) -> tuple[pa.Table, dict[str, str]]:
    """The table and the channels' columns with each column's unit from a line of units appended to its name
    (``gyro_x [rad/s]``), so that the units are guessed from them as from a name that says its unit."""
    if units is None:
        return table, columns
    names = [f"{name} [{unit}]" if unit else name for name, unit in zip(table.column_names, units)]
    renamed = dict(zip(table.column_names, names))
    return table.rename_columns(names), {channel: renamed[column] for channel, column in columns.items()}


def _require_numbers(path: Path, table: pa.Table, columns: dict[str, str]) -> None:
    """Refuse in one line a chosen column (channel -> column of ``table``) that holds text where numbers (or, for
    the time, dates and times) belong, naming its first value: a line of units under the header, say."""
    for channel, name in columns.items():
        column = table.column(name)
        if (channel == "time" and holds_clock(column)) or _numbers(table, name) is not None:
            continue
        first = next((v for v in column.to_pylist() if v is not None), None)
        raise InputError(
            f"{path}: column {name!r} ({channel}) holds text, not numbers (its first value {first!r}): a line of "
            "units under the header, or a column of another kind? Remove the line, or map the channel to another "
            "column"
        )


def _time_unit(name: str, values: np.ndarray, stated: tuple[float, str] | None = None) -> tuple[str, str]:
    """The time unit of the column ``name`` from its name, else its values' median step, and why; ``stated``, the
    (rate [Hz], name) a file of arrays states, times a time that steps by one (a sample index) first."""
    steps = np.diff(values)
    counted = steps.size > 0 and bool(np.all(steps == 1))
    if counted and stated is not None:
        unit = "s" if stated[0] == 1 else f"1/{stated[0]:g} s"
        return unit, (
            f"time unit {unit}: the time steps by one (a sample index as often as seconds) and the file's "
            f"{stated[1]} says {stated[0]:g} Hz"
        )
    for word in _words(name):
        if word in _TIME_UNIT_WORDS:
            return _TIME_UNIT_WORDS[word], f"time unit {_TIME_UNIT_WORDS[word]}: " + _NAMED_SO
    period = float(np.median(steps[steps > 0])) if np.any(steps > 0) else float("nan")
    for unit, factor in _TIME_FACTORS:
        if _PERIOD_RANGE_S[0] <= period * factor <= _PERIOD_RANGE_S[1]:
            why = f"time unit {unit}: the median step {period:.4g} is {1 / (period * factor):.4g} Hz in {unit}"
            if counted:  # 0, 1, 2, ...: the samples' index as often as a time in s
                why += " (check: whole numbers counting by one are a sample index as often; its period is then the unit, '100 ms' at 10 Hz)"
            return unit, why
    return "s", f"time unit s: the median step {period:.4g} fits no usual rate; check it"


def _only_increases(values: np.ndarray | None) -> bool:
    return values is not None and values.size > 2 and bool(np.all(np.diff(values) > 0))


def _find_columns(path: Path, table: pa.Table, rate_hz: float | None = None) -> tuple[dict[str, str], list[str]]:
    """Channel to column, time first, and why (see the module); refuses a table without time or gyro columns.
    With a nominal rate [Hz], the table has no time column and none is looked for."""
    names = table.column_names
    columns: dict[str, str] = {}
    reasons: list[str] = []
    if rate_hz is not None:
        names = [n for n in names if n != "time"]  # the nominal time read_headerless adds
    for name in names:
        kind = _kind(name)
        axis = _axis(name)
        channel = "temperature" if kind == "temperature" else f"{kind}_{axis}" if kind and axis else None
        if channel and channel not in columns:
            columns[channel] = name
            reasons.append(f"{channel} = {name!r}: its name")
    if not any(c.startswith("gyro_") for c in columns) and _kind(path.stem) == "gyro":
        for name in names:  # columns named x, y and z alone in a file named for the gyro (Sensor Logger's)
            if name.strip().lower() in ("x", "y", "z") and f"gyro_{name.strip().lower()}" not in columns:
                columns[f"gyro_{name.strip().lower()}"] = name
                reasons.append(f"gyro_{name.strip().lower()} = {name!r}: its name, in a file named {path.name!r}")
    if not any(c.startswith("gyro_") for c in columns):
        raise InputError(
            f"{path}: no column looks like a gyro axis (a name with gyr, omega or rate and x, y or z); "
            f"its columns are {', '.join(names)}{_vectors_hint(table)}{_one_sensor_hint([*names, path.stem])}"
        )
    if rate_hz is not None:
        reasons.insert(0, f"time: row n at n / {rate_hz:g} s (the rate given; the table has no time column)")
        return columns, reasons
    time_name = next((n for n in names if set(_words(n)) & _TIME_WORDS and n not in columns.values()), None)
    if time_name is None:
        rising = [n for n in names if n not in columns.values() and _only_increases(_numbers(table, n))]
        counters = [n for n in rising if set(_words(n)) & _COUNTER_WORDS]
        others = [n for n in rising if n not in counters]
        if others:
            time_name = others[0]
            reasons.append(f"time = {time_name!r}: the first column that only increases")
        elif counters:
            time_name = counters[0]
            reasons.append(
                f"time = {time_name!r}: a counter, the only column that only increases; its period is not in the "
                "file: give it as the time unit (time-unit = '10 ms' at 100 Hz)"
            )
    else:
        reasons.append(f"time = {time_name!r}: its name")
    if time_name is None:
        raise NoTimeColumn(
            f"{path}: no column looks like the time (named time or timestamp, or only increasing); "
            "give the rows' sample rate (rate_hz=50), or map the time column in a project file's [read.columns] "
            '(time = "NAME")'
        )
    return {"time": time_name, **columns}, reasons


def _accel_unit(table: pa.Table, columns: dict[str, str]) -> tuple[str, str]:
    accel = [_numbers(table, columns[c]) for c in ("accel_x", "accel_y", "accel_z") if c in columns]
    hinted = {w for c in columns if c.startswith("accel") for w in _words(columns[c])}
    if hinted & {"mps2", "ms2", "m", "si"}:
        return "m/s2", "accelerometer in m/s2: " + _NAMED_SO
    if "mg" in hinted:
        return "mg", "accelerometer in mg: " + _NAMED_SO
    if not accel or not all(a is not None and a.size for a in accel):
        return "g", "accelerometer in g: the default"
    n = min(a.size for a in accel)
    norm = (
        float(np.median(np.sqrt(sum(a[:n] ** 2 for a in accel))))
        if len(accel) == 3
        else float(np.max(np.abs(np.concatenate(accel))))
    )
    what = "norm" if len(accel) == 3 else "largest value"
    unit, size = min(_ACCEL_NORMS, key=lambda u: abs(np.log(max(norm, 1e-12) / u[1])))
    if norm > _COUNTS_MIN and abs(np.log(norm / size)) > np.log(_COUNTS_RATIO):
        per_g = _counts_per_g(norm)
        return f"1/{per_g:g} g", (
            f"accelerometer in raw counts, 1/{per_g:g} g: its {what} at rest is {norm:.5g}, near 1 g in no unit "
            "(check the part's range)"
        )
    return unit, f"accelerometer in {unit}: its {what} at rest is {norm:.3g}"


#: an accelerometer's norm at rest farther than this factor from 1 g in every unit, and above _COUNTS_MIN (a 10-bit
#: part over +-16 g counts 32 per g; a norm of a few g is a log that moves, not counts), is in raw counts
_COUNTS_RATIO = 1.5
_COUNTS_MIN = 20.0
#: the counts per g of an InvenSense part at its power-on range (+-2 g), whose gyro then counts 131 per deg/s
#: (+-250 deg/s): MPU-6050, MPU-9250, ICM-20600 family
_INVENSENSE_DEFAULT_PER_G, _INVENSENSE_DEFAULT_PER_DPS = 16384, 131


def _counts_per_g(norm: float) -> float:
    """The counts per g of a raw accelerometer whose norm at rest is ``norm``: the nearest power of two (the full
    scale of an ADC over a range of 2, 4, 8 or 16 g) when within 10 %, else the norm rounded to 3 digits."""
    power = 2.0 ** round(np.log2(norm))
    return power if abs(norm / power - 1.0) < 0.1 else float(f"{norm:.3g}")


#: the largest median |gyro| over all axes [deg/s] a gyro in deg/s gives while still or turning about one axis (the
#: others' biases); more is mdps (or raw counts)
_MAX_REST_DPS = 50.0


def _gyro_unit(table: pa.Table, columns: dict[str, str], accel_unit: str) -> tuple[str, str]:
    words = {w for c in columns if c.startswith("gyro") for w in _words(columns[c])}
    if words & {"rad", "rads", "radps"}:
        return "rad/s", "gyro in rad/s: " + _NAMED_SO
    if words & {"mrad", "mrads"}:
        return "mrad/s", "gyro in mrad/s: " + _NAMED_SO
    if "mdps" in words:
        return "mdps", "gyro in mdps: " + _NAMED_SO
    if words & {"dps", "deg", "degs"}:
        return "deg/s", "gyro in deg/s: " + _NAMED_SO
    if accel_unit == f"1/{_INVENSENSE_DEFAULT_PER_G} g":
        return f"1/{_INVENSENSE_DEFAULT_PER_DPS} deg/s", (
            f"gyro in raw counts, 1/{_INVENSENSE_DEFAULT_PER_DPS} deg/s: the accelerometer counts "
            f"{_INVENSENSE_DEFAULT_PER_G} per g, an InvenSense part's power-on range (+-2 g), where its gyro "
            f"counts {_INVENSENSE_DEFAULT_PER_DPS} per deg/s (+-250 deg/s; check the part's range)"
        )
    if accel_unit.startswith("1/"):
        return "deg/s", (
            "gyro in deg/s: the default, but the accelerometer is in raw counts: the gyro's scale cannot be told at "
            f"rest; give the part's (gyro-unit = '1/{_INVENSENSE_DEFAULT_PER_DPS} deg/s' for 131 counts per deg/s)"
        )
    gyro = [_numbers(table, columns[c]) for c in columns if c.startswith("gyro_")]
    typical = float(np.median(np.abs(np.concatenate(gyro)))) if all(g is not None and g.size for g in gyro) else 0.0
    if typical > _MAX_REST_DPS:
        return "mdps", (
            f"gyro in mdps: its typical size, {typical:.4g}, is no rate in deg/s while still (check: raw "
            "counts need the part's scale)"
        )
    if accel_unit == "m/s2":
        return "rad/s", (
            "gyro in rad/s: the accelerometer is in m/s2, and a logger that writes SI does so throughout "
            "(check: a bias at rest cannot tell rad/s from deg/s)"
        )
    return "deg/s", "gyro in deg/s: the default (check: a bias at rest cannot tell rad/s from deg/s)"


def _guessed_units(
    table: pa.Table, columns: dict[str, str], stated: tuple[float, str] | None = None
) -> tuple[str, str, str, tuple[str, str, str]]:
    """The time, accelerometer and gyro units of the channels ``columns`` (channel -> column of ``table``), and why
    (``stated``: the sample rate a file of arrays states, :func:`_time_unit`)."""
    if "time" in columns and holds_clock(table.column(columns["time"])):
        time_unit, why_time = "s", "time unit s: the column holds dates and times, read as seconds"
    elif "time" in columns:
        time_unit, why_time = _time_unit(columns["time"], _numbers(table, columns["time"]), stated)
    else:
        time_unit, why_time = "s", "time unit s: the nominal time"
    accel_unit, why_accel = _accel_unit(table, columns)
    gyro_unit, why_gyro = _gyro_unit(table, columns, accel_unit)
    return time_unit, accel_unit, gyro_unit, (why_time, why_accel, why_gyro)


def _columns_timed(
    path: Path, table: pa.Table, check: TableLayout, preamble: list[str]
) -> tuple[dict[str, str], list[str], TableLayout]:
    """:func:`_find_columns`, and where the table has no time and no rate was given, the rate its preamble states
    (:func:`_stated_rate`; else :class:`NoTimeColumn`); the layout ``check`` with that rate."""
    try:
        columns, reasons = _find_columns(path, table, check.rate_hz)
    except NoTimeColumn:
        stated = _stated_rate(preamble)
        if stated is None:
            raise
        check = TableLayout(names=check.names, rate_hz=stated[0])
        columns, reasons = _find_columns(path, table, check.rate_hz)
        reasons[0] = (
            f"time: row n at n / {stated[0]:g} s (the rate the preamble states, {stated[1]!r}; the table has no time "
            "column)"
        )
    return columns, reasons, check


def guess_layout(
    path, names: tuple[str, ...] | None = None, rate_hz: float | None = None, fmt: str | None = None
) -> LayoutGuess:
    """Guess the column mapping and units of a CSV/TSV or Parquet table from its first ``GUESS_ROWS`` rows (see
    the module), or of a file of named arrays (HDF5/NetCDF, MAT-file, ``.npz``) from its arrays' names; refuses a
    file of another format, or one whose time or gyro columns cannot be told.

    Parameters
    ----------
    path : path
        The table.
    names : tuple of str, optional
        A table without a header line (a serial terminal's log): its columns' names in order. Without them such
        a table raises :class:`HeaderlessTable`, saying how many numbers its rows hold.
    rate_hz : float, optional
        The rows' nominal sample rate [Hz], for a table without a time column.
    fmt : str, optional
        The file's format (default: told from its name, then its first bytes): ``csv`` for a text table of
        another name (MATLAB's ``save -ascii`` output named ``.mat``), ``parquet``, ``hdf5`` or ``mat``.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such file")
    if fmt is None:  # a table by its name; without names given, a file of named arrays by its first bytes too
        fmt = detect_table_format(path) or (detect_format(path) if names is None else None)
    if fmt in _NAMED_ARRAYS and names is None:
        return _guess_arrays(path, _NAMED_ARRAYS[fmt](path), rate_hz)
    if fmt not in ("csv", "parquet"):
        raise InputError(
            f"{path}: not a CSV/TSV or Parquet table, nor a file of named arrays (HDF5, MAT, .npz); logs (ULog, "
            "DataFlash, ROS bags) need no layout"
        )
    check = TableLayout(names=names, rate_hz=rate_hz)  # names and rate checked as every reader checks them
    units = None
    if names is not None:
        table, delimiter, preamble = read_headerless(path, check.names, check.rate_hz).slice(0, GUESS_ROWS), None, []
    else:
        table, delimiter, preamble, units = _sample(path, fmt)
    columns, reasons, check = _columns_timed(path, table, check, preamble)
    _require_numbers(path, table, columns)
    time_unit, accel_unit, gyro_unit, why = _guessed_units(*_with_units(table, columns, units))
    if units is not None:
        reasons.append(f"a line of units under the header ({', '.join(units)}): read for the units, not as a row")
    layout = TableLayout(
        columns,
        gyro_unit=gyro_unit,
        accel_unit=accel_unit,
        time_unit=time_unit,
        names=check.names,
        rate_hz=check.rate_hz,
    )
    unused = tuple(n for n in table.column_names if n not in columns.values() and not (check.rate_hz and n == "time"))
    return LayoutGuess(str(path), layout, (*reasons, *why), unused)


#: the formats of named arrays a layout is guessed for, and how their first rows are sampled
_NAMED_ARRAYS = {"hdf5": lambda path: sample_hdf5(path, GUESS_ROWS), "mat": lambda path: load_arrays(path)[0]}


#: names of a list that names a matrix's columns (numpy's and pandas' ``columns``, MATLAB importdata's
#: ``colheaders``), alone or after the matrix's name (``data_columns``, ``data/colheaders``)
_COLUMN_LABELS = ("columns", "colheaders", "column_names", "names", "labels", "header")


def _entries(store: ArrayStore) -> list[tuple[str, str, np.ndarray]]:
    """(name to map, name to read the channel from, values) of each array, and of each column of a matrix that a list
    of names of its width names (``data[:, 0]`` read as ``gyro_x_dps``, its label): a list beside it or in the same
    structure (MATLAB importdata's ``data`` and ``colheaders``)."""
    entries = [(name, name.rsplit("/", 1)[-1], array[()]) for name, array in store.items()]
    for name, array in store.items():
        if array.ndim != 2:
            continue
        for key, labels in store.labels.items():
            owner, _, last = key.rpartition("/") if "/" in key else ("", "", key)
            last = last.removeprefix(f"{name}_")
            if (
                len(labels) == array.shape[1]
                and last in _COLUMN_LABELS
                and owner in ("", name, name.rpartition("/")[0])
            ):
                values = array[()]
                entries += [(f"{name}[:, {k}]", label, values[:, k]) for k, label in enumerate(labels)]
                break
    return entries


def _time_then_axes(values: np.ndarray) -> bool:
    """Whether ``values`` is an (n, 4) array of the time then three axes (``[t x y z]``, as MATLAB logs keep a
    sensor's buffer): its first column never falls and rises overall, and no other column does so."""
    if values.ndim != 2 or values.shape[1] != 4 or values.shape[0] < 2 or not np.issubdtype(values.dtype, np.number):
        return False
    steps = np.diff(values, axis=0)
    rising = np.all(steps >= 0, axis=0) & (values[-1] > values[0])
    return bool(rising[0] and not rising[1:].any())


def _triads(values: np.ndarray) -> int:
    """How many x, y, z triads an (n, 3k) array of numbers holds (0 for any other shape)."""
    if values.ndim != 2 or values.shape[1] % 3 or not np.issubdtype(values.dtype, np.number):
        return 0
    return values.shape[1] // 3


def _axes_by_column(kind: str, name: str, values: np.ndarray, first: int) -> dict[str, tuple[str, np.ndarray]]:
    """The x, y and z axes of ``kind`` as columns ``first`` to ``first + 2`` of the array ``name``: channel ->
    (``NAME[:, k]``, its values)."""
    return {f"{kind}_{axis}": (f"{name}[:, {k}]", values[:, k]) for k, axis in enumerate("xyz", start=first)}


def _array_channels(store: ArrayStore) -> tuple[dict[str, str], list[str], dict[str, tuple[str, np.ndarray]]]:
    """Channel -> array of each array named as a channel (an (n, 3) gyro or accelerometer array whole, an (n, 4)
    one of the time then the axes by its columns, one of one dimension per axis, the temperature, the time; a
    matrix's column by its label), why, and the per-axis columns (``NAME[:, k]`` -> values)."""
    columns: dict[str, str] = {}
    reasons: list[str] = []
    flat: dict[str, tuple[str, np.ndarray]] = {}
    for name, base, values in _entries(store):
        kind = "time" if set(_words(base)) & _TIME_WORDS else _kind(base)
        said = "its name" if base == name.rsplit("/", 1)[-1] else f"its label, {base!r}"
        if kind in ("gyro", "accel") and values.ndim == 2 and values.shape[1] == 3 and kind not in columns:
            columns[kind] = name
            reasons.append(f"{kind} = {name!r}: {said}, an (n, 3) array")
            flat.update(_axes_by_column(kind, name, values, 0))
        elif kind in ("gyro", "accel") and _triads(values) > 1 and not {kind, f"{kind}_x"} & set(columns):
            axes = _axes_by_column(kind, name, values, 0)
            flat.update(axes)
            columns.update({channel: column for channel, (column, _) in axes.items()})
            reasons.append(
                f"{kind}_x, _y, _z = {name!r} columns 0 to 2: {said}, an (n, {values.shape[1]}) array of "
                f"{_triads(values)} triads, the first taken (check: Android keeps the calibrated one first, the "
                "uncalibrated after it)"
            )
        elif kind in ("gyro", "accel") and _time_then_axes(values) and not {kind, f"{kind}_x"} & set(columns):
            axes = _axes_by_column(kind, name, values, 1)
            flat.update(axes)
            columns.update({channel: column for channel, (column, _) in axes.items()})
            reasons.append(
                f"{kind}_x, _y, _z = {name!r} columns 1 to 3: {said}, an (n, 4) array whose first column never "
                "falls (the time)"
            )
            if "time" not in columns:
                columns["time"] = f"{name}[:, 0]"
                flat["time"] = (f"{name}[:, 0]", values[:, 0])
                reasons.append(f"time = '{name}[:, 0]': the first column of {name!r}")
        elif kind in ("time", "temperature") and values.ndim == 1 and kind not in columns:
            columns[kind] = name
            reasons.append(f"{kind} = {name!r}: {said}")
            flat[kind] = (name, values)
        elif kind in ("gyro", "accel") and values.ndim == 1 and _axis(base) and f"{kind}_{_axis(base)}" not in columns:
            channel = f"{kind}_{_axis(base)}"
            columns[channel] = name
            reasons.append(f"{channel} = {name!r}: {said}")
            flat[channel] = (base if base != name.rsplit("/", 1)[-1] else name, values)
    return columns, reasons, flat


#: words of a number in a file of arrays that states its sample rate [Hz] (``fs_hz``, ``rate_hz``, ``sample_rate``)
_RATE_WORDS = {"fs", "rate", "hz", "freq", "frequency", "odr", "samplerate"}


def _stated_array_rate(store: ArrayStore) -> tuple[float, str] | None:
    """(rate [Hz], its name) of the first single number whose name says it is the sample rate, within the
    plausible range."""
    for name, value in store.scalars.items():
        if set(_words(name.rsplit("/", 1)[-1])) & _RATE_WORDS and (
            _STATED_RATE_RANGE_HZ[0] <= value <= _STATED_RATE_RANGE_HZ[1]
        ):
            return value, name
    return None


def _vectors_hint(table: pa.Table) -> str:
    """For a table without a gyro column per axis: its columns of vectors (lists or structs per row), if any."""
    vectors = [f for f in table.schema if pa.types.is_nested(f.type)]
    return "".join(f"; column {f.name!r} {vector_column(f.type)}" for f in vectors)


def _one_sensor_hint(names: list[str]) -> str:
    """For a file without a gyro whose names (its columns' or arrays', its own) say the accelerometer or the
    temperature: that a log's channels are read from one file (a logger that writes a file per sensor)."""
    found = {_kind(n) for n in names}
    kinds = [k for k in ("accel", "temperature") if k in found]
    if not kinds or "gyro" in found:  # a gyro named without its axes is no file of another sensor
        return ""
    held = " and the ".join("accelerometer" if k == "accel" else k for k in kinds)
    return (
        f"; it holds the {held} without the gyro (a logger's file per sensor): gyrocomp reads a log's channels from "
        "one file, so join the sensors' files into one table first"
    )


def _guess_arrays(path: Path, store: ArrayStore, rate_hz: float | None) -> LayoutGuess:
    """The layout of a file of named arrays: the channels from the arrays' names (:func:`_array_channels`), the
    units from the names and the magnitudes as for a table's columns (a column k of an array is ``NAME[:, k]``)."""
    columns, reasons, flat = _array_channels(store)
    if not any(c == "gyro" or c.startswith("gyro_") for c in columns):
        shapes = ", ".join(f"{n} {tuple(a.shape)}" for n, a in store.items())
        alone = _one_sensor_hint([n.rsplit("/", 1)[-1] for n in store] + [path.stem])
        raise InputError(
            f"{path}: no array looks like the gyro (a name with gyr, omega or rate: an (n, 3) array, an (n, 4) one "
            f"of the time then x, y, z, or one per axis named with x, y or z); its arrays are {shapes}: map them "
            f'in a project file\'s [read.columns] (gyro_x = "NAME[:, k]" for column k of an array){alone}'
        )
    stated = _stated_array_rate(store)
    if stated is not None and "time" not in columns and rate_hz is None:
        rate_hz = stated[0]
        reasons.insert(0, f"time: sample n at n / {rate_hz:g} s (the file's {stated[1]} = {rate_hz:g}; no time array)")
    elif "time" not in columns and rate_hz is not None:
        reasons.insert(0, f"time: sample n at n / {rate_hz:g} s (the rate given; no time array)")
    if "time" not in columns and rate_hz is None:
        raise NoTimeColumn(
            f"{path}: no array looks like the time (named time, t or timestamp); give the samples' rate "
            '(rate_hz=50), or map the time array in a project file\'s [read.columns] (time = "NAME")'
        )
    n = min(len(values) for _, values in flat.values())
    table = pa.table({column: np.asarray(values[:n], dtype=float) for column, values in flat.values()})
    named = {channel: column for channel, (column, _) in flat.items()}
    # an array's units attribute is what the reader applies: guessed from as a name that says its unit is
    attributes = {name: str(array.attrs.get("units") or "").split(" since ")[0] for name, array in store.items()}
    stated_units = tuple(attributes.get(column.split("[", 1)[0], "") for column in table.column_names)
    time_unit, accel_unit, gyro_unit, why = _guessed_units(*_with_units(table, named, stated_units), stated)
    why = tuple(w.replace(_NAMED_SO, "its array's units attribute says so") for w in why)
    units = [name for name, array in store.items() if name in columns.values() and array.attrs.get("units")]
    if units:
        reasons.append(f"the units attributes of {', '.join(units)} are read from the file and win over these")
    layout = TableLayout(columns, gyro_unit=gyro_unit, accel_unit=accel_unit, time_unit=time_unit, rate_hz=rate_hz)
    used = [value.split("[", 1)[0] for value in columns.values()]  # a matrix read by its columns is used
    unused = tuple(name for name in store if name not in used)
    return LayoutGuess(str(path), layout, (*reasons, *why), unused)


__all__ = ["GUESS_ROWS", "HeaderlessTable", "LayoutGuess", "NoTimeColumn", "guess_layout"]
