"""The isolator as a mechanism: the parallel leaf-spring guide and what it does."""
