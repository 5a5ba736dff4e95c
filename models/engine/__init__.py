"""The event engine: one event loop (Sec. II C) with dense and sparse backends."""
