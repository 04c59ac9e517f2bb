"""The documents: the report of a result directory (:mod:`.sections`, :mod:`.problem`, read by :mod:`.results`),
of a sweep (:mod:`.sweep`), of the studies (:mod:`.studies`) and of the paper (:mod:`.paper`; its runs are the
study :mod:`validation.studies.paper_problem`)."""
