"""ARINC-424 procedure database: fixed-column records, leg records, the database and its selection of
flyable sequences (runway, procedure, transitions)."""
