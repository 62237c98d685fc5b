"""The paper's simplified formulas for design measures (section 4, eq. 22-32).
**The simplified formulas** (one body at one temperature, one environment, no internal
resistance) make the heat stiffness K_alpha = 1 / sum(alpha_i A_i), so the heat stiffness
ratio of eq. 22 is lambda_tr = K_alpha1 / K_alpha2 = sum_after / sum_before:

- eq. 25 (as it must read; the paper prints it upside down, which gives lambda < 1 against
  its own eq. 26 and text): lambda_I = (sum(alpha_i A_i) + alpha_M1 A_M1) / sum(alpha_i A_i);
- eq. 26: lambda_I = 1 + A_M1 / sum(A_i) (all coefficients equal);
- eq. 27 / 28: lambda_II = 1 + sum_j (alpha_M2 - alpha_j) A_j / sum(alpha_i A_i);
- eq. 29 / 30: lambda_III = lambda_I + lambda_II - 1;
- eq. 24: Delta T = T1 (lambda - 1) / lambda;  eq. 32: xi = (lambda - 1) / lambda 100 %;
- eq. 31: lambda = K_Q2 / K_Q1 for the growth; for the uniform body the growth is
  proportional to its rise (eq. 20), so the formulas predict the same lambda.

Here sum(alpha_i A_i) runs over **every surface of the spec with a film coefficient**, at
the case's speed, coolant jacket included (:func:`compare.design.stiffness.surface_films`)."""

from __future__ import annotations

#: the paper's recommended range of the heat stiffness ratio (section 4): 1.1 < lambda <= 5..6
PAPER_LAMBDA_RANGE = (1.1, 6.0)


def lambda_added(sum_alpha_A_W_K: float, alpha_M_W_m2K: float, A_M_m2: float) -> float:
    """Eq. 25 in its consistent form: (sum(alpha_i A_i) + alpha_M A_M) / sum(alpha_i A_i)."""
    return (sum_alpha_A_W_K + alpha_M_W_m2K * A_M_m2) / sum_alpha_A_W_K


def lambda_added_as_printed(sum_alpha_A_W_K: float, alpha_M_W_m2K: float, A_M_m2: float
                            ) -> float:
    """Eq. 25 exactly as the paper prints it (the reciprocal of :func:`lambda_added`, < 1 for
    any added surface); kept only to document the misprint."""
    return sum_alpha_A_W_K / (sum_alpha_A_W_K + alpha_M_W_m2K * A_M_m2)


def lambda_added_equal_alpha(A_M_m2: float, sum_A_m2: float) -> float:
    """Eq. 26: 1 + A_M / sum(A_i), every coefficient equal."""
    return 1.0 + A_M_m2 / sum_A_m2


def lambda_improved(sum_alpha_A_W_K: float, alpha_M2_W_m2K: float,
                    alphas_W_m2K: list[float], areas_m2: list[float]) -> float:
    """Eq. 27: 1 + sum_j (alpha_M2 - alpha_j) A_j / sum(alpha_i A_i) over the k improved
    surfaces j (coefficients alpha_j, areas A_j)."""
    gain = sum((alpha_M2_W_m2K - a) * A for a, A in zip(alphas_W_m2K, areas_m2, strict=True))
    return 1.0 + gain / sum_alpha_A_W_K


def lambda_improved_equal_alpha(alpha_M2_W_m2K: float, alpha_W_m2K: float, sum_A_k_m2: float,
                                sum_A_m2: float) -> float:
    """Eq. 28: 1 + (alpha_M2 / alpha - 1) sum(A_k) / sum(A_i), every other coefficient alpha."""
    return 1.0 + (alpha_M2_W_m2K / alpha_W_m2K - 1.0) * sum_A_k_m2 / sum_A_m2


def lambda_both(sum_alpha_A_W_K: float, alpha_M_W_m2K: float, A_M_m2: float,
                alpha_M2_W_m2K: float, alphas_W_m2K: list[float], areas_m2: list[float]) -> float:
    """Eq. 29: lambda_I + lambda_II - 1."""
    return (lambda_added(sum_alpha_A_W_K, alpha_M_W_m2K, A_M_m2)
            + lambda_improved(sum_alpha_A_W_K, alpha_M2_W_m2K, alphas_W_m2K, areas_m2) - 1.0)


def lambda_both_equal_alpha(A_M_m2: float, alpha_M2_W_m2K: float, alpha_W_m2K: float,
                            sum_A_k_m2: float, sum_A_m2: float) -> float:
    """Eq. 30: 1 + A_M / sum(A_i) + (alpha_M2 / alpha - 1) sum(A_k) / sum(A_i)."""
    return 1.0 + A_M_m2 / sum_A_m2 + (alpha_M2_W_m2K / alpha_W_m2K - 1.0) * sum_A_k_m2 / sum_A_m2


def xi_pct(lam: float) -> float:
    """Eq. 32: reduction of the excess temperature [%], (lambda - 1) / lambda 100."""
    return (lam - 1.0) / lam * 100.0


def lambda_from_xi(xi: float) -> float:
    """Eq. 32 inverted: lambda = 1 / (1 - xi / 100)."""
    return 1.0 / (1.0 - xi / 100.0)


def temperature_drop_K(T1_rise_K: float, lam: float) -> float:
    """Eq. 24: Delta T = T1 (lambda - 1) / lambda [K] (T1: the excess temperature before)."""
    return T1_rise_K * (lam - 1.0) / lam
