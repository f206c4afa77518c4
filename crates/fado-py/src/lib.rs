//! fado-py
