//! Pure numerics. Nothing in here performs IO, spawns threads or knows about the
//! service: functions take inputs (SI units) and a progress/cancel callback and return
//! results or a typed error.
