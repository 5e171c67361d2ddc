//! Tests of the volume loaders: the eight real volumes of `../shared/data` against the facts in
//! its README, NIfTI originals against their NRRD twins, round trips of generated NRRD, NIfTI and
//! raw files, and every kind of bad input (clear error naming the file, never a panic, never an
//! unbounded allocation).

mod bad_data;
mod bad_files;
mod dicom_hostile;
mod dicom_mosaic;
mod dicom_shared;
mod dicom_written;
mod metaimage;
mod nifti_nibabel;
mod nifti_round_trip;
mod nrrd_round_trip;
mod orientation;
mod pydicom_conformance;
mod real_data;
mod sampled;
mod tiff_stacks;
mod zarr_python;
mod zarr_written;
