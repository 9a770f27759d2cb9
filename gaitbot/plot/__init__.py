"""The plot room: pictures of trajectories and eigen-gait models (matplotlib, the ``plot`` extra).

Above the gait room and beside sim: it draws what the gait room made and imports nothing else.
"""

from gaitbot.plot.figures import plot_eigen_model, plot_trajectory

__all__ = ["plot_trajectory", "plot_eigen_model"]
