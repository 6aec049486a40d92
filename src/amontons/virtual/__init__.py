"""The virtual experiment: raw data with known truth, written in the layout real data follows."""
