"""The plotting tests draw off screen (Agg), wherever they run."""

import matplotlib

matplotlib.use("Agg")
