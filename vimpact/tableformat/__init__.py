"""The format of a vimpact restitution table, shared by its writer and its reader.

The sweep (:mod:`vimpact.sweep`) writes tables and the lookup (:mod:`vimpact.lookup`)
reads them; both use this package, which imports neither:

- :mod:`vimpact.tableformat.schema`: the columns with their units and meaning, the
  row statuses, the schema version;
- :mod:`vimpact.tableformat.metadata`: the metadata codec (``vimpact.<key>`` entries,
  an encode/decode pair);
- :mod:`vimpact.tableformat.integrity`: content and metadata hashes, read-back
  verification (:func:`~vimpact.tableformat.integrity.verify_table`);
- :mod:`vimpact.tableformat.files`: atomic writes, no symbolic links, the output lock;
- :mod:`vimpact.tableformat.parameters`: the friction incidence ``psi`` of a row.
"""
