"""Verification studies: grid convergence (GCI), accuracy against the reference, the study
and its report, regression baselines, sensor choice and the pytest plugin."""
