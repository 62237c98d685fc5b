"""Closing the loop with bench data: the grey-box model, its FEM anchor, calibration and
effect selection, residual diagnostics, synthetic bench runs and the fit report."""
