//! SIRDS benchmark rows (placeholder replaced below).
