"""more-agent: MORE (mobile manipulation rearrangement through grounded language reasoning).

Subpackages: ``sim`` (embedded BEHAVIOR-1K world), ``mapping`` (maps and Voronoi graphs),
``scene_graph`` (hierarchical scene graph), ``llm`` (clients, cache, prompts), ``planners``
(MORE, MoMa-LLM variants, oracle), ``eval`` (episodes, metrics, reports), ``viz`` (pictures).
"""

__version__ = "0.1.0"
