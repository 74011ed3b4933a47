"""Production calibration of fleets: many units fitted on Dask into a calibration store, judged against limits,
and compared with their population.

- :mod:`~gyrocomp.fleet.devices`: which runs belong to which unit (a path pattern or a manifest), input hashes;
- :mod:`~gyrocomp.fleet.unit_figures`: a unit's figures of merit;
- :mod:`~gyrocomp.fleet.limits`: pass/fail limits (TOML) and verdicts;
- :mod:`~gyrocomp.fleet.store`: the calibration store (SQLite or any SQLAlchemy database), with history;
- :mod:`~gyrocomp.fleet.run`: the fleet fit itself (Dask local cluster, a running cluster, or serial);
- :mod:`~gyrocomp.fleet.stations`: several fleet fits (stations) on one store, each unit claimed by one;
- :mod:`~gyrocomp.fleet.certify`: a unit's held-out residual for its certificate, from its runs checked again;
- :mod:`~gyrocomp.fleet.population`: the fleet table, robust outlier scores, yield;
- :mod:`~gyrocomp.fleet.prior`: a new unit from a short run, with the fleet's population as the prior.

Needs the ``fleet`` extra (``pip install 'gyrocomp[fleet]'``: dask[distributed], SQLAlchemy; a PostgreSQL store
the ``postgresql`` extra: psycopg).
"""

from .unit_figures import FIGURE_NAMES, REFERENCE_TEMPERATURE_DEGC, AxisFigures, UnitFigures, unit_figures
from .limits import Failure, Limit, Limits, Verdict
from .population import FleetYield, fleet_table, fleet_yield, robust_z
from .prior import (
    AxisPrior,
    PopulationPrior,
    block_covariance,
    comes_back,
    fit_with_prior,
    population_prior,
    prior_from_models,
)
from .model_files import FLEET_TABLE, MODELS_FOLDER, model_file_name
from .run import FleetSettings, FleetSummary, UnitOutcome, fit_fleet, fit_unit
from .store import CalibrationRecord, CalibrationStore, InputFile, parse_time, store_url, utc_now
from .devices import UnitRuns, expand_inputs, input_hash, units_from_manifest, units_from_pattern

__all__ = [
    "AxisPrior",
    "PopulationPrior",
    "block_covariance",
    "comes_back",
    "fit_with_prior",
    "population_prior",
    "prior_from_models",
    "AxisFigures",
    "CalibrationRecord",
    "CalibrationStore",
    "FIGURE_NAMES",
    "FLEET_TABLE",
    "Failure",
    "FleetSettings",
    "FleetSummary",
    "FleetYield",
    "InputFile",
    "Limit",
    "Limits",
    "MODELS_FOLDER",
    "REFERENCE_TEMPERATURE_DEGC",
    "UnitFigures",
    "UnitOutcome",
    "UnitRuns",
    "Verdict",
    "expand_inputs",
    "fit_fleet",
    "fit_unit",
    "fleet_table",
    "fleet_yield",
    "input_hash",
    "model_file_name",
    "parse_time",
    "robust_z",
    "store_url",
    "units_from_manifest",
    "units_from_pattern",
    "unit_figures",
    "utc_now",
]
