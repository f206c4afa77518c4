//! fado-sim
