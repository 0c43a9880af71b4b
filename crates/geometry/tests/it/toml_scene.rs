//! A TOML scene using every table and key of the format.
