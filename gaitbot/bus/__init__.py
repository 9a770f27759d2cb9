"""The bus room: one abstract servo bus, one module per backend, and a recording mock port."""
