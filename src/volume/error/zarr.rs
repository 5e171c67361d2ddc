//! Errors from reading OME-Zarr stores (`crate::volume::zarr`).

/// What is wrong with an OME-Zarr store, in words a user can act on.
#[derive(Debug, thiserror::Error)]
pub enum ZarrError {
    /// The folder (or address) holds no Zarr metadata at all.
    #[error(
        "this is not a Zarr store: it holds no zarr.json (Zarr v3) and no .zgroup, .zattrs or \
         .zarray (Zarr v2)"
    )]
    NotAStore,
    /// A remote store could not be reached or set up.
    #[error("the store at {address} cannot be read: {reason}")]
    Remote {
        /// The address.
        address: String,
        /// What the client said.
        reason: String,
    },
    /// A remote store refused the request's credentials (or their absence).
    #[error("the store refused the request's credentials ({takes}): {reason}")]
    Credentials {
        /// Which credentials the address's scheme takes, from where.
        takes: &'static str,
        /// What the server said.
        reason: String,
    },
    /// The store's root is a group without OME multiscales.
    #[error(
        "the Zarr group holds no OME-Zarr image: its attributes have no 'multiscales' (open the \
         image's own group, or one of its arrays)"
    )]
    NoMultiscales,
    /// The NGFF metadata cannot be used.
    #[error("the OME-Zarr metadata is not valid: {0}")]
    Metadata(String),
    /// zarrs could not open the group or an array (missing or invalid metadata, a codec or data
    /// type it does not read).
    #[error("the Zarr {what} '{path}' cannot be opened: {reason}")]
    Open {
        /// `group` or `array`.
        what: &'static str,
        /// The node's path in the store.
        path: String,
        /// What zarrs reported.
        reason: String,
    },
    /// The array's samples are of a type LeapView does not store.
    #[error(
        "the Zarr array holds {name} samples; LeapView reads uint8, int8, uint16, int16, uint32, \
         int32, float32 and float64"
    )]
    DataType {
        /// The data type as zarrs names it.
        name: String,
    },
    /// One chunk (or shard's inner chunk) would decode to more than LeapView allows.
    #[error(
        "the Zarr array's chunks of {shape:?} samples are larger than {limit} each; rechunk the \
         store",
        limit = crate::text::bytes(*.limit_bytes)
    )]
    ChunkTooLarge {
        /// The chunk's shape.
        shape: Vec<u64>,
        /// The largest chunk accepted, in bytes.
        limit_bytes: u64,
    },
    /// An axis holds more than one entry and is neither time, channel nor space.
    #[error(
        "the image's axis '{name}' has {size} entries; LeapView reads one time point and one \
         channel of 3 space axes"
    )]
    ExtraAxis {
        /// The axis's name.
        name: String,
        /// Its length.
        size: u64,
    },
    /// The time point or channel asked for is past the image's last.
    #[error("there is no {axis} {asked}: the image has {count} ({flag} 1 to {count})")]
    NoSuchIndex {
        /// `time point` or `channel`.
        axis: &'static str,
        /// The flag that chooses it.
        flag: &'static str,
        /// What was asked for, counted from 1.
        asked: u64,
        /// How many there are.
        count: u64,
    },
    /// Every chunk of the level failed to read.
    #[error("no chunk of the Zarr array '{path}' could be read (the first: {first})")]
    Unreadable {
        /// The array's path in the store.
        path: String,
        /// The first failure.
        first: String,
    },
}
