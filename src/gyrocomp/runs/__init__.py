"""Runs: recordings prepared for a fit once (:mod:`gyrocomp.runs.prepared`), and a long log cut into runs
(:mod:`gyrocomp.runs.runsplit`). Above :mod:`gyrocomp.recording` and :mod:`gyrocomp.motion`, which it uses."""
