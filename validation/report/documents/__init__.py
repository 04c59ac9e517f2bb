"""The documents: the report of a result directory (:mod:`.sections`, with :data:`.sections.SECTIONS`
and the problem statement of :mod:`.problem`, read by :mod:`.results`), of a sweep
(:mod:`.sweep`), of the studies (:mod:`.studies`) and of the paper's test problem
(:mod:`.paper`, its cases run by :mod:`.paper_runs`)."""
