"""Everything written or printed: the result dictionary and trajectory, the output folder, the
figures, the cam table, the comparison with the source, the law comparison and the key-point check."""
