"""Runs side by side: two runs compared (compare), a measured run read and compared, the engines' agreement
over random designs."""
