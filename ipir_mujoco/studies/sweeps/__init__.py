"""What-if sweeps over many designs (the sweep study): the design space, the streamed and resumable results
file, the metrics of a run, the results as a DataFrame."""
