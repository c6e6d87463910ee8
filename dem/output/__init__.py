"""What a run leaves behind: its folder (one run per folder, checkpoints, resume: :mod:`dem.output.folder`), the
files written as it goes (time series, VTU/PVD snapshots, summary: :mod:`dem.output.writer`), plots
(:mod:`dem.output.plots`) and rendered frames (:mod:`dem.output.frames`)."""
