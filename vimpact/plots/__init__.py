"""Figures drawn from the code's own runs (the thesis's figures and more)."""
