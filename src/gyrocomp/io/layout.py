"""A table's layout: which column holds each channel, in what unit, with what separators, or without a header
line (the names and a nominal rate); each field a reading option (:mod:`gyrocomp.option_spelling`)."""

from __future__ import annotations

import json
import warnings
from dataclasses import dataclass

from ..errors import DataQualityWarning, InputError, user_stacklevel
from ..recording import ACCEL_AXES, GYRO_AXES, REFERENCE_RATE_AXES, TEMPERATURE_COLUMN
from ..option_spelling import Spelling, spelled
from ..units import unit_factor
from .serial import check_rate, parse_names, parse_rate

TIME_COLUMN = "time"
#: the time "column" of a table read with a nominal rate: no column of the file, row n at n / rate [s]
NOMINAL_TIME = "\x00row / rate"
#: the most columns a table without a header line may name (a row is at most 1 kB of text)
MAX_NAMES = 40
PER_AXIS_TEMPERATURES = tuple(f"{TEMPERATURE_COLUMN}_{a[-1]}" for a in GYRO_AXES)
CANONICAL_COLUMNS = (
    TIME_COLUMN,
    *GYRO_AXES,
    *ACCEL_AXES,
    TEMPERATURE_COLUMN,
    *PER_AXIS_TEMPERATURES,
    *REFERENCE_RATE_AXES,
)
#: channels a mapping may name as one (n, 3) array, in formats that hold arrays (HDF5/NetCDF)
ARRAY_CHANNELS = ("gyro", "accel")


def unit_named(name: str) -> str:
    """The canonical column ``name`` with the suffix of its unit at the interfaces, as the project names things
    (``time_s``, ``gyro_x_dps``, ``accel_x_g``, ``temperature_degc``, ``ref_rate_x_dps``): a file whose
    names say those units is read without a mapping."""
    if name == TIME_COLUMN:
        return "time_s"
    if name.startswith(TEMPERATURE_COLUMN):
        return name + "_degc"
    return name + ("_g" if name in ACCEL_AXES else "_dps")


#: a channel mapped to this is not read (``columns={"time": ""}``, ``--columns time=``): the time only, for a file
#: whose time stamps are not the samples' (taken as buffered samples arrived), read at ``rate_hz`` instead
UNMAPPED = ""


def parse_column_mapping(text: str | None) -> dict[str, str]:
    """Parse ``"gyro_z=GyrZ,temperature=T"`` into ``{"gyro_z": "GyrZ", "temperature": "T"}``; a comma inside
    brackets belongs to the column (``gyro_x=imu[:, 0]``, a column of an HDF5 array); a column in double quotes is
    taken as written, commas, equals signs and spaces included (``gyro_z="g=z, 2"``; a JSON string, ``\\"`` for a
    quote: :func:`gyrocomp.option_spelling.mapping_text` quotes so); ``time=`` leaves the time unread
    (:data:`UNMAPPED`)."""
    if not text:
        return {}
    mapping = {}
    for item in _mapping_items(text):
        if not item.strip():
            continue
        if "=" not in item:
            raise InputError(f"columns: {item.strip()!r} is not CHANNEL=COLUMN (e.g. gyro_z=GyrZ)")
        key, value = (part.strip() for part in item.split("=", 1))
        if value.startswith('"'):
            try:
                value = json.loads(value)
            except json.JSONDecodeError:
                raise InputError(
                    f'columns: {item.strip()!r}: a quoted column is one JSON string (\\" for a quote inside it)'
                ) from None
        if not key or not value and key != TIME_COLUMN:  # time= (nothing): the time left unread, UNMAPPED
            raise InputError(f"columns: {item.strip()!r} is not CHANNEL=COLUMN (e.g. gyro_z=GyrZ)")
        mapping[key] = value
    return mapping


def _mapping_items(text: str) -> list[str]:
    """The ``CHANNEL=COLUMN`` items of a mapping's text: split at the commas outside brackets and quotes."""
    items, start, depth, quoted, escaped = [], 0, 0, False, False
    for k, c in enumerate(text):
        if quoted:
            if escaped:
                escaped = False
            elif c == "\\":
                escaped = True
            elif c == '"':
                quoted = False
        elif c == '"':
            quoted = True
        elif c == "[":
            depth += 1
        elif c == "]":
            depth = max(0, depth - 1)
        elif c == "," and depth == 0:
            items.append(text[start:k])
            start = k + 1
    if quoted:
        raise InputError(f"columns: {text!r}: a quoted column is not closed (a double quote is missing)")
    items.append(text[start:])
    return items


def _delimiter(text: str) -> str:
    """``--delimiter``'s text: ``tab`` (or ``\\t``) for a tab, ``space`` for runs of spaces and tabs, else the
    character."""
    word = text.strip().lower()
    return "\t" if word in ("tab", "\\t") else " " if word == "space" else text


@dataclass(frozen=True)
class TableLayout:
    """How a table's columns map to gyrocomp's channels, and the units they are in.

    Parameters
    ----------
    columns : dict
        Canonical channel name (``time``, ``gyro_z``, ``temperature`` ...) to the file's column name.
        Channels not named here are looked up under their canonical name.
    gyro_unit, accel_unit, time_unit : str
        Units of the file's columns, e.g. ``"rad/s"``, ``"m/s2"``, ``"ms"``.
    delimiter : str, optional
        CSV field separator; default: told from the header (comma, semicolon or tab).
    decimal : {".", ","}, optional
        CSV decimal point; default: a comma when the separator is not one and the first row's numbers have one.
    names : tuple of str, optional
        A text table without a header line (a serial terminal's log): its columns' names in order; a line is a
        row when it holds exactly that many numbers, every other line is skipped and counted
        (:mod:`gyrocomp.io.serial`).
    rate_hz : float, optional
        Nominal sample rate [Hz] of a table without a time column: the n-th row (with ``names``, the n-th line
        after the first row) is at n / rate_hz [s]. Refused for a table that has a time column.
    """

    columns: dict[str, str] = spelled(
        Spelling(
            "--columns",
            "Map channels to the file's columns, e.g. gyro_z=GyrZ,temperature=T; time= leaves the time unread "
            "(the rows then at the rate given).",
            metavar="CH=COL,...",
            parse=parse_column_mapping,
        ),
        default_factory=dict,
    )
    gyro_unit: str = spelled(
        Spelling("--gyro-unit", "deg/s, rad/s or mdps; raw counts scaled: '1/131 deg/s'."), default="deg/s"
    )
    accel_unit: str = spelled(Spelling("--accel-unit", "g, mg or m/s2; raw counts scaled: '1/16384 g'."), default="g")
    time_unit: str = spelled(Spelling("--time-unit", "s, ms, us or ns; a counter scaled: '10 ms'."), default="s")
    delimiter: str | None = spelled(
        Spelling(
            "--delimiter",
            "CSV field separator (default: told from the header: comma, semicolon, tab, or runs of spaces; 'tab' "
            "for a tab, 'space' for runs of spaces and tabs).",
            parse=_delimiter,
        ),
        default=None,
    )
    decimal: str | None = spelled(
        Spelling("--decimal", "CSV decimal point, . or , (default: told from the first row)."), default=None
    )
    names: tuple[str, ...] | None = spelled(
        Spelling(
            "--names",
            "A text table without a header line (a serial terminal's log): its columns' names in order, e.g. "
            "gyro_x,gyro_y,gyro_z,temperature; lines that are not that many numbers are skipped and counted.",
            metavar="NAME,...",
            parse=parse_names,
        ),
        default=None,
    )
    rate_hz: float | None = spelled(
        Spelling(
            "--rate",
            "Nominal sample rate [Hz] of a file without a time column, or whose time is left unread (time= in "
            "the column mapping: stamps taken as buffered samples arrived): the n-th row is at n / rate s.",
            metavar="HZ",
            parse=parse_rate,
        ),
        default=None,
    )

    def __post_init__(self) -> None:
        if self.names is not None:
            names = parse_names(self.names) if isinstance(self.names, str) else self.names
            if not isinstance(names, (list, tuple)) or not all(isinstance(n, str) for n in names):
                raise InputError(f"names: the columns' names in order, e.g. gyro_x,gyro_y,gyro_z; got {names!r}")
            if not names or any(not n.strip() for n in names):
                raise InputError(f"names: {','.join(names)!r}: an empty name; give each column a name")
            repeated = sorted({n for n in names if names.count(n) > 1})
            if repeated:
                raise InputError(f"names: {repeated[0]!r} given twice; give each column its own name")
            if len(names) > MAX_NAMES:
                raise InputError(
                    f"names: {len(names)} names; a row of a table without a header holds at most {MAX_NAMES}"
                )
            object.__setattr__(self, "names", tuple(names))
        if self.rate_hz is not None:
            object.__setattr__(self, "rate_hz", check_rate(self.rate_hz))
            if self.names is not None and TIME_COLUMN in self.names:
                raise InputError(
                    f"rate_hz: the names include {TIME_COLUMN}; a nominal rate is for tables without a time column"
                )
        elif self.columns.get(TIME_COLUMN) == UNMAPPED:
            raise InputError(
                "columns: time is left unread (columns={'time': ''}): give the samples' rate (rate_hz=100), the n-th "
                "row then at n / rate s"
            )
        for canonical, column in self.columns.items():
            if column == UNMAPPED and canonical != TIME_COLUMN:
                raise InputError(f"columns: {canonical}= names no column; only the time may be left unread (time=)")
        for canonical in self.columns:
            if canonical not in CANONICAL_COLUMNS + ARRAY_CHANNELS:
                raise InputError(
                    f"columns: unknown channel {canonical!r}; use any of {', '.join(CANONICAL_COLUMNS)} "
                    f"(or {' and '.join(ARRAY_CHANNELS)} for an (n, 3) array in HDF5/NetCDF)"
                )
        unit_factor("gyro", self.gyro_unit, "gyro_unit")
        unit_factor("accel", self.accel_unit, "accel_unit")
        unit_factor("time", self.time_unit, "time_unit")
        if self.delimiter is not None and (len(self.delimiter) != 1 or self.delimiter in '"\r\n'):
            raise InputError(f"delimiter: {self.delimiter!r}; give one character, e.g. ';' (or a tab)")
        if self.decimal not in (None, ".", ","):
            raise InputError(f"decimal: {self.decimal!r}; use '.' or ','")

    def resolve(self, header: list[str], source: str) -> dict[str, str]:
        """Canonical name to file column for every channel present in ``header``.

        Parameters
        ----------
        header : list of str
            The table's column names.
        source : str
            The file's name, for messages.

        Returns
        -------
        dict
            Canonical channel (``time``, ``gyro_z``, ``temperature`` ...) to the column that holds it.
        """
        resolved = {name: name for name in CANONICAL_COLUMNS if name in header}
        unread = {name for name, column in self.columns.items() if column == UNMAPPED}  # the time= of a mapping
        # the standard names (or with their unit: gyro_z_dps) also match whatever their case and surrounding spaces
        # (" Gyro_Z" is gyro_z); two columns that both match one name (Gyro_Z and GYRO_Z) are refused, naming both,
        # unless a mapping says
        for name in CANONICAL_COLUMNS:
            matches = [column for column in header if column.strip().lower() == name]
            if not matches:  # the name with its unit: time_s, gyro_x_dps, temperature_degc
                matches = [column for column in header if column.strip().lower() == unit_named(name)]
            if len(matches) > 1 and name not in self.columns:
                raise InputError(
                    f"{source}: columns {' and '.join(map(repr, matches))} would both be read as "
                    f"{name}; say which with columns={{{name!r}: {matches[0]!r}}} (or rename one)"
                )
            if name not in resolved and matches and matches[0] not in resolved.values():
                resolved[name] = matches[0]
        for name in unread:
            resolved.pop(name, None)
        for canonical, column in self.columns.items():
            if column == UNMAPPED:
                continue
            if canonical in ARRAY_CHANNELS:
                raise InputError(
                    f"{source}: columns={{{canonical!r}: {column!r}}}: a table has one column per axis; "
                    f"map {canonical}_x=..., {canonical}_y=..., {canonical}_z=... instead"
                )
            if column not in header:
                raise InputError(
                    f"{source}: columns={{{canonical!r}: {column!r}}}: no column {column!r}; "
                    f"the file has {', '.join(header)}"
                )
            resolved[canonical] = column
        self._check_claims(resolved, header, source)
        return resolved

    def _check_claims(self, resolved: dict[str, str], header: list[str], source: str) -> None:
        """One column feeds one channel; a channel's own column left unread by a mapping is said."""
        readers: dict[str, list[str]] = {}
        for canonical, column in resolved.items():
            readers.setdefault(column, []).append(canonical)
        for column, channels in readers.items():
            if len(channels) > 1 and not all(c.startswith(TEMPERATURE_COLUMN) for c in channels):
                mapped = {c: self.columns[c] for c in channels if c in self.columns}
                raise InputError(
                    f"{source}: column {column!r} would be read as {' and '.join(channels)} "
                    f"(columns={mapped}); one column feeds one channel. To swap axes map both, "
                    "e.g. columns={'gyro_x': 'gyro_z', 'gyro_z': 'gyro_x'}"
                )
        unread = [c for c in self.columns if c in header and c not in readers and self.columns[c] not in (c, UNMAPPED)]
        for canonical in unread:
            warnings.warn(
                f"{source}: column {canonical!r} is not read: columns={{{canonical!r}: {self.columns[canonical]!r}}} "
                f"reads {canonical} from {self.columns[canonical]!r}; where the output keeps the table, "
                f"{canonical!r} stays as it was",
                DataQualityWarning,
                stacklevel=user_stacklevel(),
            )
