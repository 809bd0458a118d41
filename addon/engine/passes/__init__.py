"""One module per pass. A pass declares its ShaderSpec(s), inputs, outputs, formats and units in its
docstring; it never allocates its own outputs (the method does, once)."""
