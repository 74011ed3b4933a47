"""A small multilayer perceptron trained by Levenberg-Marquardt, and the network temperature model.

The reference thesis (M. Ali, METU, 2014, section 2.5.3) compensates temperature with a
back-propagation network of 1 input, one hidden layer of 3 tanh neurons and a linear output,
trained by MATLAB's ``trainlm``. This module does the same with numpy: inputs scaled to [-1, 1]
(``mapminmax``), the output standardized, Nguyen-Widrow initialization, Levenberg-Marquardt on
the analytic Jacobian (mu up x10 on a failed step, down x0.1 on a good one, as ``trainlm``), early
stopping when the validation error has not improved for ``MAX_FAIL`` epochs, several seeded
restarts with the best kept by validation error. Per-run turn-on constants are extra parameters
added to the network's output, so every power-on keeps its own constant, as for the polynomial.

Training data are the bin-balanced block means the lag/hysteresis model uses
(:mod:`gyrocomp.models.thermal`), so a million samples cost a few thousand points.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InputError, ModelError, NotFittedError
from .base import RANGE_TOLERANCE_DEGC, RANGE_TOLERANCE_FRACTION

MAX_FAIL = 6
MU_START, MU_DEC, MU_INC, MU_MAX = 1e-3, 0.1, 10.0, 1e10
MAX_EPOCHS = 300
DEFAULT_HIDDEN = (3,)
#: block means the network trains on [s]: temperature moves slowly, so 10-s means lose nothing and keep a
#: day of data to under 10,000 points per run
NETWORK_BLOCK_S = 10.0
DEFAULT_RESTARTS = 5
#: share of each run held out (as contiguous segments) to validate restarts and stop early
VALIDATION_SHARE = 0.2
VALIDATION_SEGMENTS = 10


# -- the network as plain arrays ------------------------------------------------------------------
def layer_shapes(n_inputs: int, hidden: tuple[int, ...]) -> list[tuple[int, int]]:
    """(outputs, inputs) of each weight matrix, hidden layers then the single linear output."""
    sizes = [n_inputs, *hidden, 1]
    return [(sizes[i + 1], sizes[i]) for i in range(len(sizes) - 1)]


def unpack(theta: np.ndarray, shapes: list[tuple[int, int]]) -> list[tuple[np.ndarray, np.ndarray]]:
    """Weights and biases of each layer from the flat parameter vector."""
    out, i = [], 0
    for rows, cols in shapes:
        w = theta[i: i + rows * cols].reshape(rows, cols)
        i += rows * cols
        b = theta[i: i + rows]
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


def jacobian(theta: np.ndarray, shapes, acts: list[np.ndarray]) -> np.ndarray:
    """d output / d theta (n, n_parameters), by back-propagation through tanh layers."""
    layers = unpack(theta, shapes)
    n = acts[0].shape[0]
    blocks: list[np.ndarray] = [None] * len(layers)  # type: ignore[list-item]
    delta = np.ones((n, 1))  # linear output
    for k in range(len(layers) - 1, -1, -1):
        w, _ = layers[k]
        prev = acts[k]
        dw = (delta[:, :, None] * prev[:, None, :]).reshape(n, -1)
        blocks[k] = np.hstack([dw, delta])
        if k:
            delta = (delta @ w) * (1.0 - acts[k] ** 2)
    return np.hstack(blocks)


def nguyen_widrow(shapes, rng: np.random.Generator) -> np.ndarray:
    """Initial parameters: hidden layers by Nguyen-Widrow (inputs in [-1, 1]), the output layer small."""
    parts = []
    for k, (rows, cols) in enumerate(shapes):
        if k == len(shapes) - 1:
            w = rng.uniform(-0.5, 0.5, (rows, cols))
            b = rng.uniform(-0.5, 0.5, rows)
        else:
            beta = 0.7 * rows ** (1.0 / cols)
            w = rng.uniform(-1, 1, (rows, cols))
            w *= beta / np.linalg.norm(w, axis=1, keepdims=True)
            b = beta * np.linspace(-1, 1, rows) * np.sign(w[:, 0]) if rows > 1 else np.zeros(rows)
        parts += [w.ravel(), b]
    return np.concatenate(parts)


@dataclass(frozen=True)
class TrainResult:
    """A trained network: parameters, per-run constants (scaled units), errors and epochs."""

    theta: np.ndarray
    run_constants: np.ndarray
    train_rmse: float
    validation_rmse: float
    epochs: int


# Over 60 lines on purpose: one Levenberg-Marquardt loop (damping, step, acceptance, early stop) whose state
# is shared by every branch; split, its pieces would pass that state back and forth.
def train_lm(x: np.ndarray, y: np.ndarray, w: np.ndarray, run: np.ndarray, n_runs: int, train: np.ndarray,
             shapes, rng: np.random.Generator | None, max_epochs: int = MAX_EPOCHS,
             start: np.ndarray | None = None) -> TrainResult:
    """Levenberg-Marquardt on weighted squared error of y ~ net(x) + c_run (c_0 = 0), scaled units.

    ``train`` marks the training points; the rest validate and stop the training early (with no
    validation points it runs to convergence). ``start`` (network parameters then run constants
    c_1..) continues from a previous result instead of a Nguyen-Widrow draw from ``rng``.
    """
    p = n_parameters(shapes)
    theta = np.concatenate([nguyen_widrow(shapes, rng), np.zeros(n_runs - 1)]) if start is None else start.copy()
    valid = ~train
    sw = np.sqrt(w)
    onehot = np.zeros((y.size, n_runs - 1))
    has = run > 0
    onehot[np.flatnonzero(has), run[has] - 1] = 1.0

    def predict(t):
        out, acts = forward(t[:p], shapes, x)
        return out + onehot @ t[p:], acts

    def errors(t):
        pred, _ = predict(t)
        e = (y - pred) * sw
        return e, math.sqrt(np.sum(e[train] ** 2) / np.sum(w[train]))

    def val_rmse(e):
        return math.sqrt(np.sum(e[valid] ** 2) / np.sum(w[valid])) if valid.any() else 0.0

    mu = MU_START
    e, sse = errors(theta)
    best_theta, best_val = theta.copy(), val_rmse(e)
    fails = 0
    epoch = 0
    for epoch in range(1, max_epochs + 1):
        pred, acts = predict(theta)
        jac = np.hstack([jacobian(theta[:p], shapes, acts), onehot]) * sw[:, None]
        jt, et = jac[train], e[train]
        a = jt.T @ jt
        g = jt.T @ et
        if np.max(np.abs(g)) < 1e-10:
            break
        improved = False
        while mu <= MU_MAX:
            try:
                step = np.linalg.solve(a + mu * np.eye(a.shape[0]), g)
            except np.linalg.LinAlgError:
                mu *= MU_INC
                continue
            cand = theta + step
            e_new, sse_new = errors(cand)
            if sse_new < sse:
                theta, e, sse = cand, e_new, sse_new
                mu *= MU_DEC
                improved = True
                break
            mu *= MU_INC
        if not improved:
            break
        if not valid.any():
            continue
        v = val_rmse(e)
        if v < best_val:
            best_theta, best_val, fails = theta.copy(), v, 0
        else:
            fails += 1
            if fails >= MAX_FAIL:
                break
    if not valid.any():
        best_theta = theta
    e_best, sse_best = errors(best_theta)
    return TrainResult(best_theta[:p], np.concatenate([[0.0], best_theta[p:]]), sse_best, val_rmse(e_best), epoch)


def validation_mask(run: np.ndarray, n_runs: int, share: float = VALIDATION_SHARE,
                    segments: int = VALIDATION_SEGMENTS) -> np.ndarray:
    """True for training points: each run cut into ``segments`` contiguous pieces in time, of which a
    ``share`` spread evenly across the run (never the first) is held out."""
    train = np.ones(run.size, dtype=bool)
    held = int(round(share * segments))
    picks = np.linspace(1, segments - 1, held).round().astype(int) if held else []
    for r in range(n_runs):
        idx = np.flatnonzero(run == r)
        pieces = np.array_split(idx, segments)
        for k in picks:
            train[pieces[k]] = False
    return train


# -- the frozen result -------------------------------------------------------------------------------
#: inputs a network may read: the model temperature [degC] and the specific force [g]
NETWORK_INPUTS = ("temperature", "accel_x", "accel_y", "accel_z")
ACCEL_INPUTS = ("accel_x", "accel_y", "accel_z")


@dataclass(frozen=True)
class MLPBias:
    """Fitted network shape of one axis's bias, without its turn-on constant.

    bias(inputs) = net(x(inputs)) - net(x(reference)),  x_i = 2 (clip(v_i) - min_i) / (max_i - min_i) - 1,
    net output [the axis's unit: deg/s, or g for an accelerometer] = standardized output * output_scale +
    output_mean. The thesis's network
    reads the temperature only; with ``inputs`` = temperature, accel_x, accel_y, accel_z it is the joint
    network of thesis 2.7.2 / 2.8 (``reference`` then includes a 1 g z-up orientation).
    """

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
                    raise InputError("the network reads the accelerations; the data needs accel_x, accel_y and "
                                     "accel_z columns [g]")
                cols.append(np.asarray(accel_g, dtype=float)[:, ACCEL_INPUTS.index(name)])
        return np.column_stack(cols)

    def shape(self, temperature_degc: np.ndarray, accel_g: np.ndarray | None = None) -> np.ndarray:
        """Bias shape [the axis's unit], zero at the reference inputs, held at the edges of the fitted ranges."""
        shape = self.net_dps(self.input_values(temperature_degc, accel_g)) - float(
            self.net_dps(np.asarray(self.reference)[None, :])[0])
        return shape.reshape(np.shape(temperature_degc))

    def to_dict(self) -> dict[str, Any]:
        return {"type": "mlp", "hidden": list(self.hidden), "activation": "tanh", "output": "linear",
                "inputs": list(self.inputs), "input_min": list(self.input_min), "input_max": list(self.input_max),
                "reference": list(self.reference),
                "weights": [list(layer) for layer in self.weights], "output_mean_dps": self.output_mean,
                "output_scale_dps": self.output_scale, "t_ref_degc": self.t_ref_degc,
                "t_min_degc": self.t_min_degc, "t_max_degc": self.t_max_degc}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "MLPBias":
        hidden = tuple(int(h) for h in d["hidden"])
        inputs = tuple(str(i) for i in d.get("inputs", ["temperature"]))
        if not inputs or any(i not in NETWORK_INPUTS for i in inputs):
            raise InputError(f"mlp inputs {list(inputs)}: use names from {', '.join(NETWORK_INPUTS)}")
        weights = tuple(tuple(float(v) for v in layer) for layer in d["weights"])
        shapes = layer_shapes(len(inputs), hidden)
        if [len(layer) for layer in weights] != [r * c + r for r, c in shapes]:
            raise InputError(f"mlp weights do not fit a {len(inputs)}-{'-'.join(map(str, hidden))}-1 network")
        floats = lambda key: tuple(float(v) for v in d.get(key, ()))  # noqa: E731
        return cls(hidden, weights, float(d["output_mean_dps"]), float(d["output_scale_dps"]), float(d["t_ref_degc"]),
                   float(d["t_min_degc"]), float(d["t_max_degc"]), inputs, floats("input_min"), floats("input_max"),
                   floats("reference"))


@dataclass
class MLPTemperatureModel:
    """Network temperature model, fitted per axis on block means of many runs jointly.

    Parameters
    ----------
    hidden : tuple of int
        Hidden layer sizes; the thesis's network is (3,).
    restarts : int
        Seeded initializations trained; the one with the lowest validation error is kept.
    seed : int
        The same seed gives the same networks.
    max_epochs : int

    Attributes (after ``fit``)
    --------------------------
    curves_ : dict[str, MLPBias]
    turn_on_biases_ : dict[str, np.ndarray]
    validation_rmse_dps_ : dict[str, list[float]]
        Validation RMS of every restart [deg/s].
    train_rmse_dps_ : dict[str, float]
        Weighted RMS of the final network's residuals over all block means [deg/s].
    epochs_ : dict[str, int]
    """

    hidden: tuple[int, ...] = DEFAULT_HIDDEN
    restarts: int = DEFAULT_RESTARTS
    seed: int = 0
    max_epochs: int = MAX_EPOCHS
    _fitted: bool = field(default=False, init=False, repr=False)

    def fit_blocks(self, axis: str, temperature_degc: list[np.ndarray], value: list[np.ndarray],
                   weight: list[np.ndarray], t_ref_degc: float, accel_g: list[np.ndarray] | None = None,
                   inputs: tuple[str, ...] = ("temperature",)) -> "MLPTemperatureModel":
        """Fit one axis on per-run arrays of temperature [degC], value [deg/s], weight and, for a network that
        reads them, specific force (n, 3) [g]."""
        if self.restarts < 1:
            raise InputError(f"restarts: must be at least 1, got {self.restarts}")
        if not hasattr(self, "curves_"):
            self.curves_, self.turn_on_biases_, self.validation_rmse_dps_, self.epochs_ = {}, {}, {}, {}
            self.train_rmse_dps_ = {}
        t = np.concatenate(temperature_degc)
        y = np.concatenate(value)
        w = np.concatenate(weight)
        run = np.concatenate([np.full(a.size, r) for r, a in enumerate(temperature_degc)])
        n_runs = len(temperature_degc)
        accel = None if accel_g is None else np.vstack(accel_g)
        probe = MLPBias(self.hidden, (), 0.0, 1.0, t_ref_degc, 0.0, 0.0, inputs, (0.0,) * len(inputs),
                        (0.0,) * len(inputs), (0.0,) * len(inputs))
        values = probe.input_values(t, accel)
        lo, hi = values.min(axis=0), values.max(axis=0)
        t_min, t_max = float(t.min()), float(t.max())
        if "temperature" in inputs and t_max - t_min <= 0:
            raise ModelError(f"{axis}: the temperature does not vary; a network needs a temperature range")
        n_params = n_parameters(layer_shapes(len(inputs), self.hidden)) + n_runs - 1
        if y.size < 2 * n_params:
            raise ModelError(f"{axis}: {y.size} training points for {n_params} parameters; record longer runs "
                             "or choose fewer hidden neurons")
        span = np.where(hi > lo, hi - lo, 1.0)
        x = np.where(hi > lo, 2.0 * (values - lo) / span - 1.0, 0.0)
        mean, scale = float(np.average(y, weights=w)), float(np.sqrt(np.average((y - np.average(y, weights=w)) ** 2,
                                                                                  weights=w))) or 1.0
        target = (y - mean) / scale
        train = validation_mask(run, n_runs)
        shapes = layer_shapes(len(inputs), self.hidden)
        results = []
        for k in range(self.restarts):
            rng = np.random.default_rng([self.seed, k])
            results.append(train_lm(x, target, w, run, n_runs, train, shapes, rng, self.max_epochs))
        best = min(results, key=lambda r: r.validation_rmse)
        # the restart is chosen on held-out segments; it then converges on all the data (a 1-3-1 network
        # has ten weights for thousands of points, and block noise makes the early stop premature)
        start = np.concatenate([best.theta, best.run_constants[1:]])
        every = np.ones(y.size, dtype=bool)
        final = train_lm(x, target, w, run, n_runs, every, shapes, None, self.max_epochs, start=start)
        best = TrainResult(final.theta, final.run_constants, final.train_rmse, best.validation_rmse,
                           best.epochs + final.epochs)
        layers = unpack(best.theta, shapes)
        weights = tuple(tuple(float(v) for v in np.concatenate([wt.ravel(), b])) for wt, b in layers)
        reference = tuple(t_ref_degc if name == "temperature" else (1.0 if name == "accel_z" else 0.0)
                          for name in inputs)
        curve = MLPBias(self.hidden, weights, mean, scale, t_ref_degc, t_min, t_max, tuple(inputs),
                        tuple(map(float, lo)), tuple(map(float, hi)), reference)
        at_ref = float(curve.net_dps(np.asarray(reference)[None, :])[0])
        self.curves_[axis] = curve
        self.turn_on_biases_[axis] = best.run_constants * scale + at_ref
        self.validation_rmse_dps_[axis] = [r.validation_rmse * scale for r in results]
        self.epochs_[axis] = best.epochs
        self.train_rmse_dps_[axis] = best.train_rmse * scale
        self._fitted = True
        return self

    def _check_fitted(self) -> None:
        if not self._fitted:
            raise NotFittedError("MLPTemperatureModel is not fitted yet; call fit first")


__all__ = ["ACCEL_INPUTS", "NETWORK_INPUTS", "MLPBias", "MLPTemperatureModel", "TrainResult", "forward", "jacobian", "layer_shapes", 
           "train_lm", "validation_mask"]
