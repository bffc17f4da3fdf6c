"""Handlers of the built-in functions, one module per group; each handler is ``(vm, proc)``."""
