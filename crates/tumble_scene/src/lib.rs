//! Scene files (TOML) for tumble. Work in progress.
