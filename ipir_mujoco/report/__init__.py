"""Figures and documents: the paper's figures redrawn, the validation report, sweep pictures."""
