"""The rule that chooses among held-out scores (gyrocomp.fitting.scores): one standard error, do no harm."""

from gyrocomp.calibration.candidate import Candidate
from gyrocomp.fitting.scores import CandidateScore, beats_constant, choose


def _score(folds, c=None):
    c = Candidate(2) if c is None else c
    return CandidateScore(c, tuple(folds), tuple(0.0 for _ in folds))


def test_simplest_within_one_standard_error_of_the_best_is_chosen():
    best = _score([1.0, 1.2, 1.4], Candidate(3))  # mean 1.2, SE 0.1155
    close = _score([1.1, 1.3, 1.5], Candidate(1))  # mean 1.3: within one SE
    far = _score([1.3, 1.5, 1.7], Candidate(0))  # mean 1.5: not
    b, c = choose([best, close, far], lambda k: k.complexity)
    assert b == Candidate(3) and c == Candidate(1)
    # a candidate that must earn its terms: the simpler one is 2 SE worse, so the complex one stays
    b, c = choose([best, _score([1.3, 1.5, 1.6], Candidate(1))], lambda k: k.complexity)
    assert c == Candidate(3)


def test_a_candidate_far_worse_on_one_fold_does_not_pass():
    best = _score([0.0035, 0.0043, 0.0065], Candidate(4, lag=True))
    erratic = _score([0.0030, 0.0040, 0.0400], Candidate(1))  # better on two folds, 6x worse on one
    _, c = choose([best, erratic], lambda k: k.complexity)
    assert c == Candidate(4, lag=True)


def test_do_no_harm_with_two_folds_asks_for_half_the_constants_drift_on_both():
    constant = _score([0.020, 0.033], Candidate(0))
    assert not beats_constant(_score([0.0123, 0.0167]), constant)  # 39 and 49 % less: what a walk can do by chance
    assert beats_constant(_score([0.0057, 0.0093]), constant)
    assert not beats_constant(_score([0.002, 0.020]), constant)  # far better on one leg only


def test_do_no_harm_with_more_folds_asks_for_one_standard_error_of_the_paired_gain():
    constant = _score([0.010, 0.012, 0.011, 0.013], Candidate(0))
    assert beats_constant(_score([0.008, 0.010, 0.009, 0.011]), constant)  # 0.002 less on every fold
    assert not beats_constant(_score([0.004, 0.014, 0.012, 0.014]), constant)  # mean gain 0.0005, SE 0.0016
    # when nothing beats the constant, the constant is chosen
    best, chosen = choose([_score([0.004, 0.014, 0.012, 0.014]), constant], lambda c: c.complexity, constant)
    assert best == Candidate(2) and chosen == Candidate(0)
