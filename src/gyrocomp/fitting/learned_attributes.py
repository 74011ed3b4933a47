"""The estimators' learned attributes: read before the fit, one line naming the call that fits them."""

from __future__ import annotations


from ..errors import NotFittedError


class LearnedAttributes:
    """Base of the estimators (scikit-learn style): reading a learned attribute (a name ending in ``_``, set by
    the fit) before the fit raises :class:`~gyrocomp.errors.NotFittedError` naming the estimator and the call that
    fits it (``FIT_CALL``). Other missing attributes are an ordinary AttributeError (``hasattr`` works)."""

    #: how the estimator is fitted, as the error tells the user
    FIT_CALL = "fit(recordings)"

    def __getattr__(self, name: str):
        if name.endswith("_") and not name.startswith("_"):
            raise NotFittedError(
                f"{type(self).__name__} is not fitted yet; call {self.FIT_CALL} first ({name} is learned by the fit)"
            )
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")
