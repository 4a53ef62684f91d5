"""Vectorised root finding (geometry/_roots.py): exact roots, brackets, bisection fallback."""

from __future__ import annotations

import numpy as np

from headsim.geometry._roots import solve_increasing


def test_cubic_roots_are_found_element_wise_to_the_tolerance() -> None:
    targets = np.array([-8.0, -1.0, 0.0, 0.125, 27.0])

    def f(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return x**3 - targets, 3 * x**2

    lo, hi = np.full(5, -10.0), np.full(5, 10.0)
    x, bracketed = solve_increasing(f, lo, hi, np.zeros(5), xtol=1e-14)
    assert bracketed.all()
    np.testing.assert_allclose(x, [-2.0, -1.0, 0.0, 0.5, 3.0], atol=1e-12)


def test_no_root_in_the_bracket_is_nan_and_not_bracketed() -> None:
    def f(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return x - np.array([0.5, 5.0, -5.0]), np.ones_like(x)

    x, bracketed = solve_increasing(f, np.zeros(3), np.ones(3), np.full(3, 0.2), xtol=1e-12)
    assert bracketed.tolist() == [True, False, False]
    assert x[0] == 0.5 and np.isnan(x[1:]).all()


def test_a_newton_step_leaving_the_bracket_falls_back_to_bisection() -> None:
    # arctan's Newton iteration diverges from x0 = 3 (it overshoots to ever larger |x|);
    # the bracket keeps it, and the root is still found.
    def f(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return np.arctan(x - 1.0), 1.0 / (1.0 + (x - 1.0) ** 2)

    x, bracketed = solve_increasing(f, np.array([-20.0]), np.array([20.0]), np.array([4.0]), 1e-13)
    assert bracketed[0]
    assert abs(x[0] - 1.0) < 1e-12
    # max_iter bounds the loop: two steps do not reach the root; the answer stays bracketed.
    x_few, still = solve_increasing(
        f, np.array([-20.0]), np.array([20.0]), np.array([4.0]), 1e-13, max_iter=2
    )
    assert still[0] and -20.0 <= x_few[0] <= 20.0 and abs(x_few[0] - 1.0) > 1e-6
