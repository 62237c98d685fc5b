"""The paper's thermal stiffness strategy (section 4): indicators, design measures, their
report and plots, and the calibration against the paper's figures."""
