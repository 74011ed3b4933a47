"""The network temperature curve of an axis's bias (thesis section 2.5.3), as a calibration holds it: a small
multilayer perceptron (inputs scaled to [-1, 1] as MATLAB's ``mapminmax``, tanh hidden layers, a linear output
standardized), evaluated with numpy. Training it (Levenberg-Marquardt, as MATLAB's ``trainlm``) is
:mod:`gyrocomp.fitting.network_model`'s.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from ..c_literals import c_array, c_number
from ..errors import InputError
from .protocol import CCode, RANGE_TOLERANCE_DEGC, RANGE_TOLERANCE_FRACTION, register_curve

DEFAULT_HIDDEN = (3,)
#: block means the network trains on [s]: temperature moves slowly, so 10-s means lose nothing and keep a
#: day of data to under 10,000 points per run
NETWORK_BLOCK_S = 10.0


# -- the network as plain arrays ------------------------------------------------------------------
def layer_shapes(n_inputs: int, hidden: tuple[int, ...]) -> list[tuple[int, int]]:
    """(outputs, inputs) of each weight matrix, hidden layers then the single linear output."""
    sizes = [n_inputs, *hidden, 1]
    return [(sizes[i + 1], sizes[i]) for i in range(len(sizes) - 1)]


def unpack(theta: np.ndarray, shapes: list[tuple[int, int]]) -> list[tuple[np.ndarray, np.ndarray]]:
    """Weights and biases of each layer from the flat parameter vector."""
    out, i = [], 0
    for rows, cols in shapes:
        w = theta[i : i + rows * cols].reshape(rows, cols)
        i += rows * cols
        b = theta[i : i + rows]
        i += rows
        out.append((w, b))
    return out


def n_parameters(shapes: list[tuple[int, int]]) -> int:
    return sum(r * c + r for r, c in shapes)


def forward(theta: np.ndarray, shapes, x: np.ndarray) -> tuple[np.ndarray, list[np.ndarray]]:
    """Network output (n,) for scaled inputs x (n, n_inputs), and each layer's activations."""
    acts = [x]
    layers = unpack(theta, shapes)
    a = x
    for k, (w, b) in enumerate(layers):
        z = a @ w.T + b
        a = z if k == len(layers) - 1 else np.tanh(z)
        acts.append(a)
    return a[:, 0], acts


# -- the frozen result -------------------------------------------------------------------------------
#: inputs a network may read: the model temperature [degC] and the specific force [g]
NETWORK_INPUTS = ("temperature", "accel_x", "accel_y", "accel_z")
ACCEL_INPUTS = ("accel_x", "accel_y", "accel_z")


@register_curve
@dataclass(frozen=True)
class NetworkCurve:
    """Fitted network shape of one axis's bias, without its turn-on constant.

    bias(inputs) = net(x(inputs)) - net(x(reference)),  x_i = 2 (clip(v_i) - min_i) / (max_i - min_i) - 1,
    net output [the axis's unit: deg/s, or g for an accelerometer] = standardized output * output_scale +
    output_mean. The thesis's network
    reads the temperature only; with ``inputs`` = temperature, accel_x, accel_y, accel_z it is the joint
    network of thesis 2.7.2 / 2.8 (``reference`` then includes a 1 g z-up orientation).
    """

    kind: ClassVar[str] = "mlp"

    hidden: tuple[int, ...]
    weights: tuple[tuple[float, ...], ...]  # flat per layer: W row-major then b
    output_mean: float
    output_scale: float
    t_ref_degc: float
    t_min_degc: float
    t_max_degc: float
    inputs: tuple[str, ...] = ("temperature",)
    input_min: tuple[float, ...] = ()
    input_max: tuple[float, ...] = ()
    reference: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        if not self.input_min:  # temperature only: its range and reference
            object.__setattr__(self, "input_min", (self.t_min_degc,))
            object.__setattr__(self, "input_max", (self.t_max_degc,))
            object.__setattr__(self, "reference", (self.t_ref_degc,))

    @property
    def order(self) -> str:
        return f"mlp {len(self.inputs)}-" + "-".join(map(str, self.hidden)) + "-1"

    @property
    def needs_accel(self) -> bool:
        return any(name in ACCEL_INPUTS for name in self.inputs)

    @property
    def beyond_range(self) -> str:
        return "held at its edge"

    def describe(self) -> str:
        return f"network {self.order}"

    @property
    def label(self) -> str:
        return "mlp:" + self.order.split(" ", 1)[1]

    def clamped(self) -> "NetworkCurve":
        return self  # the inputs are clipped to their fitted ranges already

    def plus_slope(self, slope_per_degc: float) -> None:
        return None  # a network's output cannot take a slope without retraining

    def c_code(self, name: str) -> CCode:
        """``name(tm, accel)``: the network, inputs scaled to [-1, 1] as fitted, tanh layers, a linear output;
        ``name_ref`` its value at the reference inputs, set by ``gyrocomp_init``."""
        shapes = layer_shapes(len(self.inputs), self.hidden)
        lines = [
            f"static double {name}(double tm, const double accel[3])",
            "{",
            "    (void)tm; (void)accel;",
            f"    double a0[{len(self.inputs)}];",
        ]
        values = ["tm" if i == "temperature" else f"accel[{ACCEL_INPUTS.index(i)}]" for i in self.inputs]
        for i, (v, lo, hi) in enumerate(zip(values, self.input_min, self.input_max)):
            lines.append(
                f"    a0[{i}] = 2.0 * (clip({v}, {c_number(lo)}, {c_number(hi)}) - {c_number(lo)}) / "
                f"{c_number(hi - lo)} - 1.0;"
                if hi > lo
                else f"    a0[{i}] = 0.0;"
            )
        prev = "a0"
        for k, ((rows, cols), flat) in enumerate(zip(shapes, self.weights)):
            activation = f"z + b{k}[r]" if k == len(shapes) - 1 else f"tanh(z + b{k}[r])"
            lines += [
                f"    static const double w{k}[{rows * cols}] = {c_array(flat[: rows * cols])};",
                f"    static const double b{k}[{rows}] = {c_array(flat[rows * cols :])};",
                f"    double a{k + 1}[{rows}];",
                f"    for (int r = 0; r < {rows}; ++r) {{",
                "        double z = 0.0;",
                f"        for (int c = 0; c < {cols}; ++c) z += {prev}[c] * w{k}[r * {cols} + c];",
                f"        a{k + 1}[r] = {activation};",
                "    }",
            ]
            prev = f"a{k + 1}"
        lines += [
            f"    return {prev}[0] * {c_number(self.output_scale)} + {c_number(self.output_mean)};",
            "}",
            f"static double {name}_ref;",
            "",
        ]
        ref = list(self.reference)
        t_ref = ref[self.inputs.index("temperature")] if "temperature" in self.inputs else 0.0
        acc = [ref[self.inputs.index(a)] if a in self.inputs else 0.0 for a in ACCEL_INPUTS]
        init = (
            f"    {{ const double ref_accel[3] = {c_array(acc)}; {name}_ref = {name}({c_number(t_ref)}, ref_accel); }}"
        )
        return CCode((f"shape = {name}(tm, acc) - {name}_ref;",), tuple(lines), (init,))

    @property
    def range_tolerance_degc(self) -> float:
        return max(RANGE_TOLERANCE_DEGC, RANGE_TOLERANCE_FRACTION * (self.t_max_degc - self.t_min_degc))

    def outside_range(self, temperature_degc: np.ndarray) -> bool:
        t = np.asarray(temperature_degc)
        tol = self.range_tolerance_degc
        return bool(np.any(t < self.t_min_degc - tol) or np.any(t > self.t_max_degc + tol))

    def _theta(self) -> np.ndarray:
        return np.concatenate([np.asarray(layer, dtype=float) for layer in self.weights])

    def net_dps(self, values: np.ndarray) -> np.ndarray:
        """Network output [deg/s] for input values (n, len(inputs)) in their units, clipped to the fitted ranges."""
        v = np.asarray(values, dtype=float).reshape(-1, len(self.inputs))
        lo, hi = np.asarray(self.input_min), np.asarray(self.input_max)
        span = np.where(hi > lo, hi - lo, 1.0)
        x = np.where(hi > lo, 2.0 * (np.clip(v, lo, hi) - lo) / span - 1.0, 0.0)
        out, _ = forward(self._theta(), layer_shapes(len(self.inputs), self.hidden), x)
        return out * self.output_scale + self.output_mean

    def input_values(self, temperature_degc: np.ndarray, accel_g: np.ndarray | None = None) -> np.ndarray:
        """The (n, len(inputs)) matrix the network reads, from temperature [degC] and specific force (n, 3) [g]."""
        t = np.asarray(temperature_degc, dtype=float).reshape(-1)
        cols = []
        for name in self.inputs:
            if name == "temperature":
                cols.append(t)
            else:
                if accel_g is None:
                    raise InputError(
                        "the network reads the accelerations; the data needs accel_x, accel_y and accel_z columns [g]"
                    )
                cols.append(np.asarray(accel_g, dtype=float)[:, ACCEL_INPUTS.index(name)])
        return np.column_stack(cols)

    def shape(self, temperature_degc: np.ndarray, accel_g: np.ndarray | None = None) -> np.ndarray:
        """Bias shape [the axis's unit], zero at the reference inputs, held at the edges of the fitted ranges."""
        shape = self.net_dps(self.input_values(temperature_degc, accel_g)) - float(
            self.net_dps(np.asarray(self.reference)[None, :])[0]
        )
        return shape.reshape(np.shape(temperature_degc))

    def to_dict(self) -> dict[str, Any]:
        return {
            "type": "mlp",
            "hidden": list(self.hidden),
            "activation": "tanh",
            "output": "linear",
            "inputs": list(self.inputs),
            "input_min": list(self.input_min),
            "input_max": list(self.input_max),
            "reference": list(self.reference),
            "weights": [list(layer) for layer in self.weights],
            "output_mean_dps": self.output_mean,
            "output_scale_dps": self.output_scale,
            "t_ref_degc": self.t_ref_degc,
            "t_min_degc": self.t_min_degc,
            "t_max_degc": self.t_max_degc,
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "NetworkCurve":
        hidden = tuple(int(h) for h in d["hidden"])
        inputs = tuple(str(i) for i in d.get("inputs", ["temperature"]))
        if not inputs or any(i not in NETWORK_INPUTS for i in inputs):
            raise InputError(f"mlp inputs {list(inputs)}: use names from {', '.join(NETWORK_INPUTS)}")
        weights = tuple(tuple(float(v) for v in layer) for layer in d["weights"])
        shapes = layer_shapes(len(inputs), hidden)
        if [len(layer) for layer in weights] != [r * c + r for r, c in shapes]:
            raise InputError(f"mlp weights do not fit a {len(inputs)}-{'-'.join(map(str, hidden))}-1 network")
        floats = lambda key: tuple(float(v) for v in d.get(key, ()))  # noqa: E731
        ranges = {key: floats(key) for key in ("input_min", "input_max", "reference")}
        given = {key: len(values) for key, values in ranges.items() if values}
        if given and (len(given) < 3 or set(given.values()) != {len(inputs)}):
            raise InputError(
                f"mlp input_min, input_max and reference: one value per input ({len(inputs)}: "
                f"{', '.join(inputs)}), not {', '.join(f'{len(v)}' for v in ranges.values())}"
            )
        if not given and inputs != ("temperature",):
            raise InputError(f"mlp inputs {list(inputs)}: input_min, input_max and reference are needed for each")
        if "temperature" in inputs and given:
            k = inputs.index("temperature")
            if not ranges["input_max"][k] > ranges["input_min"][k]:
                raise InputError(
                    f"mlp input_min/input_max of the temperature: {ranges['input_min'][k]:g}..."
                    f"{ranges['input_max'][k]:g} degC is no range; the network would read no temperature"
                )
        return cls(
            hidden,
            weights,
            float(d["output_mean_dps"]),
            float(d["output_scale_dps"]),
            float(d["t_ref_degc"]),
            float(d["t_min_degc"]),
            float(d["t_max_degc"]),
            inputs,
            floats("input_min"),
            floats("input_max"),
            floats("reference"),
        )


__all__ = [
    "ACCEL_INPUTS",
    "DEFAULT_HIDDEN",
    "NETWORK_BLOCK_S",
    "NETWORK_INPUTS",
    "NetworkCurve",
    "forward",
    "layer_shapes",
    "n_parameters",
    "unpack",
]
