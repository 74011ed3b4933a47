"""The shared static recordings, read for the noise tests and the table of docs/accuracy-tested.md.

Run ``python -m tests.real_data`` from the repository root to print the table of docs/accuracy-tested.md.
Readers for the one-off formats (.rda: rdata, NetCDF: h5py) come with the ``[test]`` extra only.
"""

from __future__ import annotations

import numpy as np

from gyrocomp.allan import allan_deviation, noise_parameters
from gyrocomp.models.options import Network, Polynomial

from ..conftest import DATASETS

ADIS = DATASETS / "smac-imudata-adis16405"
CATS = DATASETS / "skdivemove-cats-tempcal"
#: the three static periods of the CATS experiment [s since the file's start] (its README, from the package)
CATS_PERIODS_S = ((480, 92460), (92880, 183780), (184920, 268020))
#: the fit choices compared on the CATS runs: name -> fit_calibration options
CATS_CHOICES = {
    "gyrocomp poly:3, no hysteresis": dict(temperature=Polynomial(3), hysteresis="none", acceleration="none"),
    "default (auto)": {},
    "polynomial, order by CV, no hysteresis": dict(hysteresis="none"),
    "network 1-3-1": dict(temperature=Network()),
}
#: moving-average window of the held-out drift on the CATS runs [s]
CATS_WINDOW_S = 600
GALAXY = DATASETS / "skdivemove-galaxy-s5-static"
AXES = ("x", "y", "z")


def adis_sessions() -> dict[str, np.ndarray]:
    """Session name -> (1e6, 3) gyro rates [deg/s] at 100 Hz; imu1 from the .npz, the others from .rda."""
    import rdata

    sessions = {"imu1": np.load(ADIS / "adis_16405_imu1.npz")["data"][:, :3].astype(np.float64)}
    for k in range(2, 7):
        data = rdata.read_rda(ADIS / f"adis_16405_imu{k}.rda")
        sessions[f"imu{k}"] = np.asarray(next(iter(data.values())), dtype=np.float64)[:, :3]
    return sessions


def cats_runs() -> list:
    """The three static periods of the CATS tag (gravity on -z, -x, -y), 1 Hz, as Recordings [deg/s, g, degC]."""
    from gyrocomp.recording import Recording

    d = np.load(CATS / "cats_temperature_calib_1hz.npz")
    t = d["t_s"].astype(np.float64)
    runs = []
    for k, (lo, hi) in enumerate(CATS_PERIODS_S):
        m = (t >= lo) & (t < hi)
        runs.append(
            Recording(
                time_s=t[m],
                gyro_dps=np.degrees(d["gyro_mrad_s"][m].astype(np.float64) / 1000.0),
                gyro_axes=("gyro_x", "gyro_y", "gyro_z"),
                temperature_degc=d["temperature_c"][m].astype(np.float64),
                accel_g=d["acc_m_s2"][m].astype(np.float64) / 9.80665,
                accel_axes=("accel_x", "accel_y", "accel_z"),
                source=f"CATS period {k + 1}",
            )
        )
    return runs


def cats_held_out_drift(choices: dict | None = None) -> dict[str, np.ndarray]:
    """Choice -> (3 held-out runs, 3 axes) residual drift [deg/s]: each run compensated by a fit on the other two,
    drift = RMS of the CATS_WINDOW_S moving average about its mean."""
    import warnings

    from gyrocomp import apply, fit_calibration
    from gyrocomp.measures.merit import smoothed_residual_rms

    runs = cats_runs()
    out = {}
    for name, options in (choices or CATS_CHOICES).items():
        drift = np.zeros((3, 3))
        for held in range(3):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                cal = fit_calibration([r for i, r in enumerate(runs) if i != held], **options)
                comp = apply(cal, runs[held]).gyro_dps
            drift[held] = [smoothed_residual_rms(comp[:, j], CATS_WINDOW_S) for j in range(3)]
        out[name] = drift
    return out


def cats_numpy_cubic_drift() -> np.ndarray:
    """(3 held-out runs, 3 axes) drift of the field's baseline, written here with numpy alone: a cubic in the
    reported temperature centred at 15 degC with one constant per run, least squares on every sample of the
    two other runs, extrapolated as the cubic."""
    from gyrocomp.measures.merit import smoothed_residual_rms

    runs = cats_runs()
    out = np.zeros((3, 3))
    for held in range(3):
        train = [r for i, r in enumerate(runs) if i != held]
        x = np.vstack(
            [
                np.hstack([np.eye(2)[np.full(r.n_samples, k)], (r.temperature_degc - 15.0)[:, None] ** [1, 2, 3]])
                for k, r in enumerate(train)
            ]
        )
        coef, *_ = np.linalg.lstsq(x, np.vstack([r.gyro_dps for r in train]), rcond=None)
        u = (runs[held].temperature_degc - 15.0)[:, None] ** [1, 2, 3]
        comp = runs[held].gyro_dps - u @ coef[2:]
        out[held] = [smoothed_residual_rms(comp[:, j], CATS_WINDOW_S) for j in range(3)]
    return out


TOFUPILOT = DATASETS / "tofupilot-imu-thermal"


def tofupilot_run():
    """The real one-cycle chamber log (51.6 -> -17.6 -> 74.0 -> 36.3 degC, 2 Hz), read as a user reads it: the
    tab-separated file through :func:`gyrocomp.read` with its columns and units named [s, deg/s, g, degC]."""
    from gyrocomp import read
    from gyrocomp.io import TableLayout

    columns = {
        "time": "timestamp",
        "temperature": "imu.temperature",
        **{f"gyro_{a}": f"imu.gyro.{a}" for a in AXES},
        **{f"accel_{a}": f"imu.acc.{a}" for a in AXES},
    }
    return read(
        TOFUPILOT / "imu_raw_data.tsv",
        TableLayout(columns=columns, gyro_unit="rad/s", accel_unit="m/s2", time_unit="us"),
    )


#: the methods of the one-cycle protocol: name -> a function of the fit rows giving a Calibration (None: raw)
def one_cycle_methods() -> dict:
    from gyrocomp import fit
    from gyrocomp.evaluation.comparison import fit_ardupilot_style, fit_px4_style
    from gyrocomp.evaluation.validation import fit_plain_cubic

    return {
        "raw": None,
        "plain cubic": lambda r: fit_plain_cubic([r]),
        "PX4 cubic": lambda r: fit_px4_style([r]),
        "ArduPilot cubic": lambda r: fit_ardupilot_style([r]),
        "gyrocomp default": lambda r: fit([r]),
    }


def tofupilot_one_cycle(methods: dict | None = None) -> dict[str, np.ndarray]:
    """Method -> (3,) standard deviation of each compensated axis over the final cooling leg [deg/s], by the
    dataset's protocol: fitted on the rows up to the hottest point (one cooling and one heating leg), applied to
    the whole run (a memory model sees the turn), judged on the rows after it."""
    import warnings

    from gyrocomp import apply

    run = tofupilot_run()
    hot = int(np.argmax(run.temperature_degc))
    train = run.take(np.arange(hot + 1))
    out = {}
    for name, method in (methods or one_cycle_methods()).items():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            gyro = run.gyro_dps if method is None else apply(method(train), run).gyro_dps
        out[name] = gyro[hot + 1 :].std(axis=0)
    return out


#: the shared still recordings a branch-free temperature effect is added to (name -> (series at 2 Hz [deg/s]))
STILL_RATE_HZ = 2.0


def still_series() -> dict[str, np.ndarray]:
    """Real still recordings brought to 2 Hz by block means [deg/s]: each axis of the six ADIS16405 sessions
    (100 Hz), of the Galaxy S5 (10 Hz), and two clocks of the Stable32 references (an OCXO and a caesium clock,
    their fractional frequency scaled to a 60 s drift of 0.01 deg/s: a noise shape, not a gyro)."""
    import gzip

    def means(x, factor):
        n = x.shape[0] // factor * factor
        return x[:n].reshape((n // factor, factor) + x.shape[1:]).mean(axis=1)

    out = {}
    for name, gyro in adis_sessions().items():
        for j, axis in enumerate(AXES):
            out[f"ADIS16405 {name} {axis}"] = means(gyro, 50)[:, j]
    galaxy = means(galaxy_gyro_dps(), 5)
    for j, axis in enumerate(AXES):
        out[f"Galaxy S5 {axis}"] = galaxy[:, j]
    stable32 = DATASETS / "allantools-stable32"
    ocxo = (np.loadtxt(stable32 / "ocxo" / "ocxo_frequency.txt") - 1e7) / 1e7
    with gzip.open(stable32 / "Cs5071A" / "5071A_phase.txt.gz", "rt") as fh:
        caesium = np.diff(np.loadtxt(fh))[: 6 * 9600]
    for name, y in (("OCXO (Stable32)", ocxo), ("Cs 5071A (Stable32)", caesium)):
        smooth = np.convolve(y - y.mean(), np.ones(120) / 120, mode="valid")
        out[name] = 0.01 * y / np.std(smooth)
    return out


def one_cycle_profile_degc(n: int) -> np.ndarray:
    """A one-cycle chamber profile of ``n`` samples, 40 -> -20 -> 70 -> 30 degC at one ramp rate [degC]."""
    points = np.array([40.0, -20.0, 70.0, 30.0])
    legs = np.abs(np.diff(points))
    return np.interp(np.linspace(0.0, 1.0, n), np.concatenate([[0.0], np.cumsum(legs) / legs.sum()]), points)


def still_with_temperature_effect(noise: np.ndarray, amplitude_dps: float, rng: np.random.Generator):
    """A real still series [deg/s] with a branch-free temperature effect added along
    :func:`one_cycle_profile_degc`: a cubic in (T - 25) / 45 with random coefficients scaled so that their
    absolute values sum to ``amplitude_dps`` [deg/s]; heating and cooling follow the one curve. Returns the
    recording fitted on (up to the hottest point) and the whole one."""
    from gyrocomp.recording import Recording

    temperature = one_cycle_profile_degc(noise.size)
    u = (temperature - 25.0) / 45.0
    c = rng.normal(size=3)
    effect = amplitude_dps * (c[0] * u + c[1] * u**2 + c[2] * u**3) / np.abs(c).sum()
    run = Recording(
        time_s=np.arange(noise.size) / STILL_RATE_HZ,
        gyro_dps=(noise - noise.mean() + effect)[:, None],
        gyro_axes=("gyro_x",),
        temperature_degc=temperature,
        source="still + temperature effect",
    )
    return run.take(np.arange(int(np.argmax(temperature)))), run


def still_one_cycle_trials(amplitudes_dps=(0.05, 0.5), minutes: float = 80.0, seed: int = 0) -> list[dict]:
    """Every 80-minute window of every :func:`still_series` with each amplitude of temperature effect added
    (:func:`still_with_temperature_effect`), fitted by the default call on the rows up to the hottest point and
    applied to the whole run. Per trial: ``name``, ``amplitude_dps``, ``chosen`` (the default's candidate), and
    the drift on the cooling leg after the hottest point [deg/s] (RMS about its mean of the 60 s moving average)
    of ``default``, ``cubic`` (:func:`gyrocomp.evaluation.validation.fit_plain_cubic`), ``perfect`` (the
    recording's own noise) and ``raw``."""
    import warnings

    from gyrocomp import apply, fit
    from gyrocomp.evaluation.validation import fit_plain_cubic
    from gyrocomp.measures.merit import smoothed_residual_rms

    rng = np.random.default_rng(seed)
    window = int(minutes * 60 * STILL_RATE_HZ)
    smooth = int(60 * STILL_RATE_HZ)
    out = []
    for name, series in still_series().items():
        for start in range(0, series.size - window + 1, window):
            noise = series[start : start + window]
            for amplitude in amplitudes_dps:
                train, run = still_with_temperature_effect(noise, amplitude, rng)
                hot = train.n_samples
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    default, cubic = fit([train]), fit_plain_cubic([train])
                    drift = {
                        label: smoothed_residual_rms(apply(cal, run).gyro_dps[hot:, 0], smooth)
                        for label, cal in (("default", default), ("cubic", cubic))
                    }
                out.append(
                    {
                        "name": name,
                        "amplitude_dps": amplitude,
                        "chosen": default.report.selection["gyro_x"].chosen,
                        **drift,
                        "perfect": smoothed_residual_rms(noise[hot:], smooth),
                        "raw": smoothed_residual_rms(run.gyro_dps[hot:, 0], smooth),
                    }
                )
    return out


XSENS = DATASETS / "imu_tk-xsens"
FERRARIS = DATASETS / "imucal-ferraris"
MPU = DATASETS / "tomisuarez2-mpu6050"
#: poses held by hand last a few seconds: shorter static segments than the default 10 s [s]
POSE_MIN_S = {"Xsens (imu_tk)": 3.0, "imucal Ferraris session": 3.0, "MPU-6050 (tomisuarez2)": 1.5}


def _unit_sphere(accel: np.ndarray, rec_for_segments) -> np.ndarray:
    """Accelerometer counts to [g] by the ellipsoid through the static means: sum_j p_j (a_j - c_j)^2 = 1."""
    from gyrocomp.motion.positions import static_segments

    means = np.array([s.gravity_g for s in static_segments(rec_for_segments, min_duration_s=3.0)])
    mid, spread = means.mean(axis=0), np.abs(means - means.mean(axis=0)).max()
    x = (means - mid) / spread  # conditioning
    design = np.column_stack([x**2, x, np.ones(len(x))])
    coef, *_ = np.linalg.lstsq(design, np.ones(len(x)), rcond=None)
    p, q, r = coef[:3], coef[3:6], coef[6]
    centre = -q / (2 * p)
    k = 1 - r + np.sum(p * centre**2)
    return np.sqrt(p / k) * ((accel - mid) / spread - centre)


def multi_position_recordings() -> dict:
    """The three hand-placed multi-position sessions as Recordings [deg/s, g] (no temperature)."""
    from gyrocomp.recording import Recording

    gyro_axes, accel_axes = ("gyro_x", "gyro_y", "gyro_z"), ("accel_x", "accel_y", "accel_z")
    out = {}
    g = np.loadtxt(XSENS / "xsens_gyro.mat")
    a = np.loadtxt(XSENS / "xsens_acc.mat")
    gyro = np.degrees(g[:, 1:] / 6258.0)  # imu_tk's scale: 1/6258 (rad/s)/count; the offset is a bias
    raw = Recording(time_s=g[:, 0], gyro_dps=gyro, gyro_axes=gyro_axes, accel_g=a[:, 1:], accel_axes=accel_axes)
    out["Xsens (imu_tk)"] = Recording(
        time_s=g[:, 0],
        gyro_dps=gyro,
        gyro_axes=gyro_axes,
        accel_g=_unit_sphere(a[:, 1:], raw),
        accel_axes=accel_axes,
        source="imu_tk-xsens",
    )
    f = np.genfromtxt(FERRARIS / "example_ferraris_session.csv", delimiter=",", names=True)
    out["imucal Ferraris session"] = Recording(
        time_s=f["n_samples"] / 102.4,
        gyro_dps=np.column_stack([f["gyr_x"], f["gyr_y"], f["gyr_z"]]),
        gyro_axes=gyro_axes,
        accel_g=np.column_stack([f["acc_x"], f["acc_y"], f["acc_z"]]) / 9.80665,
        accel_axes=accel_axes,
        source="imucal-ferraris",
    )
    m = np.loadtxt(MPU / "example_data_calibration.csv", delimiter=",", skiprows=5)
    out["MPU-6050 (tomisuarez2)"] = Recording(
        time_s=np.arange(len(m)) / 100.0,
        gyro_dps=m[:, 3:] / 131.0,
        gyro_axes=gyro_axes,
        accel_g=m[:, :3] / 16384.0,
        accel_axes=accel_axes,
        source="tomisuarez2-mpu6050",
    )
    return out


def g_sensitivity_fits() -> dict:
    """Dataset -> Calibration with G only (one power-on each, no temperature)."""
    import warnings

    from gyrocomp import fit_calibration

    fits = {}
    for name, rec in multi_position_recordings().items():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fits[name] = fit_calibration(
                [rec], temperature=None, acceleration="matrix", static_min_duration_s=POSE_MIN_S[name]
            )
    return fits


def main_g_sensitivity() -> None:
    print("| session | static poses | gyro | G accel_x | G accel_y | G accel_z | [deg/s/g], +- standard error |")
    print("|---|---:|---|---:|---:|---:|---|")
    for name, cal in g_sensitivity_fits().items():
        acc = cal.fit_report["acceleration"]
        for k, (axis, info) in enumerate(acc["axes"].items()):
            cells = [
                f"{g:+.4f} +- {e:.4f}" if e is not None else "not excited"
                for g, e in zip(info["g_sensitivity_dps_per_g"], info["standard_error_dps_per_g"])
            ]
            print(
                f"| {name if k == 0 else ''} | {acc['static_segments'][0] if k == 0 else ''} | {axis} | "
                + " | ".join(cells)
                + " | |"
            )


def galaxy_gyro_dps() -> np.ndarray:
    """(214800, 3) 'measured' (uncalibrated) gyro rates [deg/s] at 10 Hz."""
    import h5py

    with h5py.File(GALAXY / "samsung_galaxy_s5.nc", "r") as f:
        return np.degrees(np.asarray(f["angular_velocity"][:, 3:6], dtype=np.float64))


#: the Galaxy S5 log was decimated to 10 Hz with a forward/backward filter that flattens tau < ~3 s
GALAXY_FIT_TAUS_S = (3.0, 1000.0)


def noise_table(gyro_dps: np.ndarray, rate_hz: float, fit_taus_s=None) -> list:
    return [
        noise_parameters(allan_deviation(gyro_dps[:, j], rate_hz), fit_taus_s=fit_taus_s)
        for j in range(gyro_dps.shape[1])
    ]


def main() -> None:
    print(
        "| recording | axis | ARW fit [deg/sqrt(h)] | ARW read-off [deg/sqrt(h)] | B [deg/h] | at tau [s] "
        "| K [deg/h/sqrt(h)] | fit misfit |"
    )
    print("|---|---|---:|---:|---:|---:|---:|---:|")
    rows = [(f"ADIS16405 {name}", gyro, 100.0, None) for name, gyro in adis_sessions().items()]
    rows.append(("Galaxy S5 (fit 3-1000 s)", galaxy_gyro_dps(), 10.0, GALAXY_FIT_TAUS_S))
    for label, gyro, rate_hz, fit_taus_s in rows:
        for axis, n in zip(AXES, noise_table(gyro, rate_hz, fit_taus_s)):
            readoff = n.noise_density_readoff_dps_per_sqrt_hz
            print(
                f"| {label} | {axis} | {n.arw_deg_per_sqrt_h:.2f} | "
                f"{'-' if readoff is None else f'{60 * readoff:.2f}'} | {n.bias_instability_deg_per_h:.1f} | "
                f"{n.integration_time_s:.0f} | {n.rrw_deg_per_h_per_sqrt_h:.0f} | {n.fit_rms_log_residual:.0%} |"
            )


def main_bound() -> None:
    """The noise bounds of the real static recordings beside the IEEE 952 fit and, where stated, the datasheet."""
    from gyrocomp.allan.bound import bound_noise

    print(
        "| recording | axis | ARW fit [deg/sqrt(h)] | ARW bound | K bound [deg/h/sqrt(h)] | with Gauss-Markov: "
        "median / largest ratio to the curve | datasheet ARW |"
    )
    print("|---|---|---:|---:|---:|---:|---:|")
    rows = [(f"ADIS16405 {name}", gyro, 100.0, "2") for name, gyro in adis_sessions().items()]
    rows.append(("Galaxy S5", galaxy_gyro_dps(), 10.0, "-"))
    for label, gyro, rate_hz, datasheet in rows:
        record_s = gyro.shape[0] / rate_hz
        for axis, j in zip(AXES, range(gyro.shape[1])):
            curve = allan_deviation(gyro[:, j], rate_hz)
            fitted = noise_parameters(curve)
            two = bound_noise(curve, markov=False, max_tau_s=record_s / 10)
            full = bound_noise(curve, max_tau_s=record_s / 10)
            print(
                f"| {label} | {axis} | {fitted.arw_deg_per_sqrt_h:.2f} | {60 * two.white_noise_density:.2f} | "
                f"{two.random_walk * 216000.0:.1f} | {full.ratio_median:.2f} / {full.ratio_max:.2f} | {datasheet} |"
            )


def main_temperature() -> None:
    raw = np.array([[0.0] * 3] * 3)
    from gyrocomp.measures.merit import smoothed_residual_rms

    for k, run in enumerate(cats_runs()):
        raw[k] = [smoothed_residual_rms(run.gyro_dps[:, j], CATS_WINDOW_S) for j in range(3)]
    drift = {
        "cubic in T - 15 degC + run constants, numpy, every sample (the baseline)": cats_numpy_cubic_drift(),
        **cats_held_out_drift(),
    }
    cubic = next(iter(drift.values())).mean()
    print("| fit (on two runs, scored on the third) | drift x | drift y | drift z | mean [deg/s] | vs cubic |")
    print("|---|---:|---:|---:|---:|---:|")
    print(
        "| raw (no compensation) | "
        + " | ".join(f"{v:.4f}" for v in raw.mean(axis=0))
        + f" | {raw.mean():.4f} | {raw.mean() / cubic - 1:+.0%} |"
    )
    for name, d in drift.items():
        print(
            f"| {name} | " + " | ".join(f"{v:.4f}" for v in d.mean(axis=0)) + f" | {d.mean():.4f} | "
            f"{d.mean() / cubic - 1:+.0%} |"
        )


if __name__ == "__main__":
    import sys

    if "temperature" in sys.argv[1:]:
        main_temperature()
    elif "g-sensitivity" in sys.argv[1:]:
        main_g_sensitivity()
    elif "bound" in sys.argv[1:]:
        main_bound()
    else:
        main()
