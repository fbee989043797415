//! The MCAP recorder (placeholder; written next).
