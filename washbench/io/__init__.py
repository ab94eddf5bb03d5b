"""The ground floor: on-disk formats and their checks, atomic writes, where files are found."""
