"""MORE as a service for a robot stack: one decision from a scene graph (``decision``), over HTTP
(``app``: FastAPI, the ``serve`` extra)."""
