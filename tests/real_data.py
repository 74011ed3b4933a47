"""The shared static recordings, read for the noise tests and the README table.

Run ``python -m tests.real_data`` from the repository root to print the README's table.
Readers for the one-off formats (.rda: rdata, NetCDF: h5py) come with the ``[test]`` extra only.
"""

from __future__ import annotations

import numpy as np

from gyrocomp.allan import allan_deviation, noise_parameters

from .conftest import DATASETS

ADIS = DATASETS / "smac-imudata-adis16405"
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


def galaxy_gyro_dps() -> np.ndarray:
    """(214800, 3) 'measured' (uncalibrated) gyro rates [deg/s] at 10 Hz."""
    import h5py

    with h5py.File(GALAXY / "samsung_galaxy_s5.nc", "r") as f:
        return np.degrees(np.asarray(f["angular_velocity"][:, 3:6], dtype=np.float64))


#: the Galaxy S5 log was decimated to 10 Hz with a forward/backward filter that flattens tau < ~3 s
GALAXY_FIT_TAUS_S = (3.0, 1000.0)


def noise_table(gyro_dps: np.ndarray, rate_hz: float, fit_taus_s=None) -> list:
    return [noise_parameters(allan_deviation(gyro_dps[:, j], rate_hz), fit_taus_s=fit_taus_s)
            for j in range(gyro_dps.shape[1])]


def main() -> None:
    print("| recording | axis | ARW fit [deg/sqrt(h)] | ARW read-off [deg/sqrt(h)] | B [deg/h] | at tau [s] "
          "| K [deg/h/sqrt(h)] | fit misfit |")
    print("|---|---|---:|---:|---:|---:|---:|---:|")
    rows = [(f"ADIS16405 {name}", gyro, 100.0, None) for name, gyro in adis_sessions().items()]
    rows.append(("Galaxy S5 (fit 3-1000 s)", galaxy_gyro_dps(), 10.0, GALAXY_FIT_TAUS_S))
    for label, gyro, rate_hz, fit_taus_s in rows:
        for axis, n in zip(AXES, noise_table(gyro, rate_hz, fit_taus_s)):
            readoff = n.noise_density_readoff_dps_per_sqrt_hz
            print(f"| {label} | {axis} | {n.arw_deg_per_sqrt_h:.2f} | "
                  f"{'-' if readoff is None else f'{60 * readoff:.2f}'} | {n.bias_instability_deg_per_h:.1f} | "
                  f"{n.integration_time_s:.0f} | {n.rrw_deg_per_h_per_sqrt_h:.0f} | {n.fit_rms_log_residual:.0%} |")


if __name__ == "__main__":
    main()
