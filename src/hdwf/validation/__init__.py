"""The model against measurements: read and check bench data (``measurements``), the candidate
physical effects (``effects``), solving the model's variants per specimen (``campaign``),
comparison statistics (``comparison``) and the diagnosis that calibrates and ranks the effects
and builds the error ladder (``diagnosis``)."""
