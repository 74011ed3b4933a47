"""The one way to fit: :func:`fit` (``gyrocomp.fit``), calibration runs and typed options in, a frozen
:class:`~gyrocomp.calibration.Calibration` out.

The other entry points are thin wrappers kept for the calls written against them:
:func:`~gyrocomp.models.pipelines.fit_calibration` takes the options as keyword arguments,
:func:`~gyrocomp.models.pipelines.fit_pipeline` one channel and a pipeline, and
:func:`~gyrocomp.models.pipelines.fit_channels` is this function with its arguments in another order.
"""

from __future__ import annotations

from ..calibration import Calibration
from ..runs.prepared import Channel
from ..recording import Recording
from .options import FitOptions
from .pipelines import Pipeline, ScaleFactor, fit_channels


def fit(runs: list[Recording] | Recording, options: FitOptions | None = None, *,
        channels: tuple[Channel, ...] = ("gyro",), pipeline: Pipeline = "joint",
        scale_factor: ScaleFactor = "auto") -> Calibration:
    """Fit a compensation on calibration runs.

    Parameters
    ----------
    runs : list of Recording, or one
        Calibration runs, each one power-on (its own turn-on constant) [deg/s, g, degC, s].
    options : FitOptions, optional
        What to fit and how to choose (:class:`gyrocomp.models.options.FitOptions`; default ``FitOptions()``:
        every candidate the data can identify, chosen by held-out drift).
    channels : tuple of {"gyro", "accel"}
        What is modelled: the gyro (default), the accelerometer, or both (the accelerometer first, the gyro's
        g-sensitivity then reading its compensated accelerations).
    pipeline : {"joint", "poly>matrix", "matrix>poly", "mlp>matrix", "mlp>mlp-accel", "joint-mlp"}
        How the gyro's stages are fitted: together (``joint``, the default) or in the thesis's cascades
        (:func:`gyrocomp.models.pipelines.fit_pipeline`).
    scale_factor : {"auto", "none", "matrix", "matrix-temperature"}
        The gyro's scale factor and misalignment K(T), from rate-table runs or turns between still poses.

    Examples
    --------
    >>> model = gyrocomp.fit(runs)                                                # doctest: +SKIP
    >>> model = gyrocomp.fit(runs, FitOptions(hysteresis="none"), channels=("gyro", "accel"))  # doctest: +SKIP
    """
    return fit_channels(runs, channels, pipeline, scale_factor=scale_factor, options=options)


__all__ = ["fit"]
