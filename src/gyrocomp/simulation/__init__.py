"""The simulator with its exact truth (:mod:`.simulator`), the error models (:mod:`.error_model`), presets and test
profiles."""

from __future__ import annotations

from .simulator import (
    AccelErrorModel, changed_profile, COMPONENTS, flicker_bank, get_preset, get_profile, GyroErrorModel, Hysteresis,
    NoiseTruth, ONE_TEMPERATURE_PROFILES, Preset, preset_model, PRESETS, Profile, PROFILE_PARAMETERS, PROFILES,
    resolve_profile, run_profiles, simulate, simulate_noise, Simulation, Trajectory, Truth, truth_document,
    tumble_positions
)

__all__ = [
    "AccelErrorModel", "COMPONENTS", "GyroErrorModel", "Hysteresis", "NoiseTruth", "ONE_TEMPERATURE_PROFILES",
    "PRESETS", "PROFILES", "PROFILE_PARAMETERS", "Preset", "Profile", "Simulation", "Trajectory", "Truth",
    "changed_profile", "flicker_bank", "get_preset", "get_profile", "preset_model", "resolve_profile",
    "run_profiles", "simulate", "simulate_noise", "truth_document", "tumble_positions"
]
