"""The ``twin`` sub-commands, one module per group; :mod:`twin.cli` parses and dispatches.

Each module registers its sub-parsers (``add_subcommands(sub)``) with a handler per command that
only parses and prints: the work lives in the library, imported inside each handler.
"""
