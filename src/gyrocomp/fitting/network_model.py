"""Training the network temperature model: a small multilayer perceptron by Levenberg-Marquardt.

The reference thesis (M. Ali, METU, 2014, section 2.5.3) compensates temperature with a
back-propagation network of 1 input, one hidden layer of 3 tanh neurons and a linear output,
trained by MATLAB's ``trainlm``. This module does the same with numpy: inputs scaled to [-1, 1]
(``mapminmax``), the output standardized, Nguyen-Widrow initialization, Levenberg-Marquardt on
the analytic Jacobian (mu up x10 on a failed step, down x0.1 on a good one, as ``trainlm``), early
stopping when the validation error has not improved for ``MAX_FAIL`` epochs, several seeded
restarts with the best kept by validation error. Per-run turn-on constants are extra parameters
added to the network's output, so every power-on keeps its own constant, as for the polynomial.

Training data are the bin-balanced block means the lag/hysteresis model uses
(:mod:`gyrocomp.fitting.thermal`), so a million samples cost a few thousand points.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, ModelError
from .learned_attributes import LearnedAttributes
from ..curves.network import DEFAULT_HIDDEN, NetworkCurve, forward, layer_shapes, n_parameters, unpack

MAX_FAIL = 6
MU_START, MU_DEC, MU_INC, MU_MAX = 1e-3, 0.1, 10.0, 1e10
MAX_EPOCHS = 300
DEFAULT_RESTARTS = 5
#: share of each run held out (as contiguous segments) to validate restarts and stop early
VALIDATION_SHARE = 0.2
VALIDATION_SEGMENTS = 10


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
def train_lm(
    x: np.ndarray,
    y: np.ndarray,
    w: np.ndarray,
    run: np.ndarray,
    n_runs: int,
    train: np.ndarray,
    shapes,
    rng: np.random.Generator | None,
    max_epochs: int = MAX_EPOCHS,
    start: np.ndarray | None = None,
) -> TrainResult:
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
    for epoch in range(1, max_epochs + 1):  # noqa: B007  (the epochs run are returned)
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


def validation_mask(
    run: np.ndarray, n_runs: int, share: float = VALIDATION_SHARE, segments: int = VALIDATION_SEGMENTS
) -> np.ndarray:
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


@dataclass
class NetworkTemperatureModel(LearnedAttributes):
    """Network temperature model, fitted per axis on block means of many runs jointly (``fit_blocks``, one call
    per axis).

    Parameters
    ----------
    hidden : tuple of int
        Hidden layer sizes; the thesis's network is (3,).
    restarts : int
        Seeded initializations trained; the one with the lowest validation error is kept.
    seed : int
        The same seed gives the same networks.
    max_epochs : int

    Attributes (after ``fit_blocks``)
    ---------------------------------
    curves_ : dict[str, NetworkCurve]
    turn_on_biases_ : dict[str, np.ndarray]
    validation_rmse_ : dict[str, list[float]]
        Validation RMS of every restart [the axis's unit: deg/s; g for an accelerometer's axes].
    train_rmse_ : dict[str, float]
        Weighted RMS of the final network's residuals over all block means [the axis's unit].
    epochs_ : dict[str, int]
    """

    FIT_CALL = "fit_blocks(axis, ...)"

    hidden: tuple[int, ...] = DEFAULT_HIDDEN
    restarts: int = DEFAULT_RESTARTS
    seed: int = 0
    max_epochs: int = MAX_EPOCHS

    def fit_blocks(
        self,
        axis: str,
        temperature_degc: list[np.ndarray],
        value: list[np.ndarray],
        weight: list[np.ndarray],
        t_ref_degc: float,
        accel_g: list[np.ndarray] | None = None,
        inputs: tuple[str, ...] = ("temperature",),
    ) -> "NetworkTemperatureModel":
        """Fit one axis on per-run arrays of temperature [degC], value [deg/s], weight and, for a network that
        reads them, specific force (n, 3) [g]."""
        if self.restarts < 1:
            raise InputError(f"restarts: must be at least 1, got {self.restarts}")
        if not hasattr(self, "curves_"):
            self.curves_, self.turn_on_biases_, self.validation_rmse_, self.epochs_ = {}, {}, {}, {}
            self.train_rmse_ = {}
        t = np.concatenate(temperature_degc)
        y = np.concatenate(value)
        w = np.concatenate(weight)
        run = np.concatenate([np.full(a.size, r) for r, a in enumerate(temperature_degc)])
        n_runs = len(temperature_degc)
        accel = None if accel_g is None else np.vstack(accel_g)
        zeros = (0.0,) * len(inputs)
        probe = NetworkCurve(self.hidden, (), 0.0, 1.0, t_ref_degc, 0.0, 0.0, inputs, zeros, zeros, zeros)
        values = probe.input_values(t, accel)
        lo, hi = values.min(axis=0), values.max(axis=0)
        t_min, t_max = float(t.min()), float(t.max())
        if "temperature" in inputs and t_max - t_min <= 0:
            raise ModelError(f"{axis}: the temperature does not vary; a network needs a temperature range")
        n_params = n_parameters(layer_shapes(len(inputs), self.hidden)) + n_runs - 1
        if y.size < 2 * n_params:
            raise ModelError(
                f"{axis}: {y.size} training points for {n_params} parameters; record longer runs "
                "or choose fewer hidden neurons"
            )
        span = np.where(hi > lo, hi - lo, 1.0)
        x = np.where(hi > lo, 2.0 * (values - lo) / span - 1.0, 0.0)
        mean = float(np.average(y, weights=w))
        scale = float(np.sqrt(np.average((y - mean) ** 2, weights=w))) or 1.0
        shapes = layer_shapes(len(inputs), self.hidden)
        best, results = self._train(x, (y - mean) / scale, w, run, n_runs, shapes)
        weights = tuple(
            tuple(float(v) for v in np.concatenate([wt.ravel(), b])) for wt, b in unpack(best.theta, shapes)
        )
        reference = tuple(
            t_ref_degc if name == "temperature" else (1.0 if name == "accel_z" else 0.0) for name in inputs
        )
        ranges = (t_min, t_max, tuple(inputs), tuple(map(float, lo)), tuple(map(float, hi)))
        curve = NetworkCurve(self.hidden, weights, mean, scale, t_ref_degc, *ranges, reference)
        at_ref = float(curve.net_dps(np.asarray(reference)[None, :])[0])
        self.curves_[axis] = curve
        self.turn_on_biases_[axis] = best.run_constants * scale + at_ref
        self.validation_rmse_[axis] = [r.validation_rmse * scale for r in results]
        self.epochs_[axis] = best.epochs
        self.train_rmse_[axis] = best.train_rmse * scale
        return self

    def _train(self, x, target, w, run, n_runs: int, shapes) -> tuple[TrainResult, list[TrainResult]]:
        """The best of the restarts by held-out error, converged on all the data, and every restart's result."""
        train = validation_mask(run, n_runs)
        results = []
        for k in range(self.restarts):
            rng = np.random.default_rng([self.seed, k])
            results.append(train_lm(x, target, w, run, n_runs, train, shapes, rng, self.max_epochs))
        best = min(results, key=lambda r: r.validation_rmse)
        # the restart is chosen on held-out segments; it then converges on all the data (a 1-3-1 network
        # has ten weights for thousands of points, and block noise makes the early stop premature)
        start = np.concatenate([best.theta, best.run_constants[1:]])
        every = np.ones(target.size, dtype=bool)
        final = train_lm(x, target, w, run, n_runs, every, shapes, None, self.max_epochs, start=start)
        best = TrainResult(
            final.theta, final.run_constants, final.train_rmse, best.validation_rmse, best.epochs + final.epochs
        )
        return best, results


__all__ = ["NetworkTemperatureModel", "TrainResult", "jacobian", "train_lm", "validation_mask"]
