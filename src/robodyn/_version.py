"""robodyn's version (one place; ``robodyn.__version__`` re-exports it)."""

__version__ = "0.1.0"
