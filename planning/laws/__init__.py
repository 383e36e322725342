"""Motion laws: speed transitions of the crank, each a list of linear-jerk segments."""
