"""Pure message <-> domain conversions, no node state."""
