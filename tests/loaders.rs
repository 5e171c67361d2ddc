//! Tests of the volume loaders: the eight real volumes of `../shared/data` against the facts in
//! its README, NIfTI originals against their NRRD twins, round trips of generated NRRD, NIfTI and
//! raw files, and every kind of bad input (clear error naming the file, never a panic, never an
//! unbounded allocation).

mod common;

#[path = "loaders/bad_data.rs"]
mod bad_data;
#[path = "loaders/bad_files.rs"]
mod bad_files;
#[path = "loaders/nifti_round_trip.rs"]
mod nifti_round_trip;
#[path = "loaders/nrrd_round_trip.rs"]
mod nrrd_round_trip;
#[path = "loaders/orientation.rs"]
mod orientation;
#[path = "loaders/real_data.rs"]
mod real_data;
