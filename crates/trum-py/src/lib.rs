//! Python bindings: placeholder until the Python-module issue lands; see crates/trum-py/README.
