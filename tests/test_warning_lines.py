"""Every warning gyrocomp raises points at the user's line, not at the library's (issue #72, item 10)."""

import warnings

import numpy as np

from gyrocomp import apply, fit
from gyrocomp.errors import ModelChoiceWarning, PlausibilityWarning, user_stacklevel

from .conftest import chamber_run


def test_the_model_choice_and_apply_warn_at_the_callers_line():
    run = chamber_run([-10.0, 50.0], 2.0, rate_hz=2.0)  # one heating leg: the choice has little to hold out
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        cal = fit([run])
        flipped = run.take(np.arange(run.n_samples))
        apply(cal, flipped)
    ours = [w for w in caught if issubclass(w.category, (ModelChoiceWarning, PlausibilityWarning))]
    assert ours, [str(w.message) for w in caught]
    assert {w.filename for w in ours} == {__file__}, {(w.filename, w.lineno) for w in ours}


def test_outside_the_package_the_level_is_the_caller():
    def raise_here():
        warnings.warn("here", UserWarning, stacklevel=user_stacklevel())

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        raise_here()
    assert caught[0].filename == __file__ and caught[0].lineno == raise_here.__code__.co_firstlineno + 1
