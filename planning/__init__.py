"""The motion: motion laws, the press cycle, the optimizer, verification, outputs, CLI."""
