"""``Scan.lazy()``: a scan as a Polars ``LazyFrame`` through Polars' IO
plugin interface, reading one log at a time as the query asks for rows."""


def lazy_frame(scan):
    """``scan`` (a ``wobblog.Scan``) as a ``polars.LazyFrame``: each log is
    decoded when the query reaches it; the query's columns, filter and row
    limit are applied to that log's frames before the next one is read, so
    memory holds one log's frames whatever their number, and a query that
    needs few rows reads few logs."""
    import polars as pl
    from polars.io.plugins import register_io_source

    schema = pl.DataFrame(scan._empty()).schema
    parts = scan._parts()

    def source(with_columns, predicate, n_rows, batch_size):
        left = n_rows
        for part in parts:
            if left is not None and left <= 0:
                return
            frames = pl.DataFrame(part)
            if predicate is not None:
                frames = frames.filter(predicate)
            if with_columns is not None:
                frames = frames.select(with_columns)
            if left is not None:
                frames = frames.head(left)
                left -= frames.height
            yield frames

    return register_io_source(source, schema=schema, explain_name="wobblog.scan")
