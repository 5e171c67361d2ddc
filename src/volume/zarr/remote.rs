//! Stores at an address: `http://` and `https://` (any server that answers range requests with
//! 206, as object stores and most file servers do), `s3://BUCKET/PATH` (AWS or any
//! S3-compatible server, configured by the usual `AWS_*` environment variables: credentials,
//! `AWS_REGION`, `AWS_ENDPOINT_URL`, `AWS_ALLOW_HTTP`, `AWS_SKIP_SIGNATURE` for public
//! buckets), `gs://BUCKET/PATH` (Google Cloud Storage, `GOOGLE_*` variables) and
//! `az://CONTAINER/PATH` (Azure Blob Storage, `AZURE_*` variables), through `object_store`,
//! read synchronously on a tokio runtime of LeapView's own.

use std::sync::{Arc, OnceLock};

use zarrs::storage::ReadableStorageTraits;
use zarrs_object_store::AsyncObjectStore;
use zarrs_object_store::object_store::aws::AmazonS3Builder;
use zarrs_object_store::object_store::azure::MicrosoftAzureBuilder;
use zarrs_object_store::object_store::gcp::GoogleCloudStorageBuilder;
use zarrs_object_store::object_store::http::HttpBuilder;
use zarrs_object_store::object_store::prefix::PrefixStore;
use zarrs_object_store::object_store::{ClientOptions, ObjectStore};
use zarrs_storage::storage_adapter::async_to_sync::{
    AsyncToSyncBlockOn, AsyncToSyncStorageAdapter,
};

use super::address::{Cloud, Scheme};
use crate::volume::error::zarr::ZarrError;

/// The runtime the stores' requests run on: one for the process, started on first use (why
/// there is none, where it could not start).
fn runtime() -> Result<&'static tokio::runtime::Runtime, &'static str> {
    static RUNTIME: OnceLock<Result<tokio::runtime::Runtime, String>> = OnceLock::new();
    RUNTIME
        .get_or_init(|| {
            tokio::runtime::Builder::new_multi_thread()
                .worker_threads(2)
                .thread_name("store requests")
                .enable_all()
                .build()
                .map_err(|e| e.to_string())
        })
        .as_ref()
        .map_err(String::as_str)
}

/// Runs a store's futures to completion on [`runtime`] (from any thread but the runtime's own).
struct BlockOn(tokio::runtime::Handle);

impl AsyncToSyncBlockOn for BlockOn {
    fn block_on<F: core::future::Future>(&self, future: F) -> F::Output {
        self.0.block_on(future)
    }
}

/// The store at `address`.
pub(super) fn open(address: &str) -> Result<Arc<dyn ReadableStorageTraits>, ZarrError> {
    let refused = |reason: String| ZarrError::Remote {
        address: address.to_string(),
        reason,
    };
    let store: Arc<dyn ObjectStore> = match Scheme::of(address) {
        Some(Scheme::Http) | None => Arc::new(
            HttpBuilder::new()
                .with_url(address.trim_end_matches('/'))
                .with_client_options(ClientOptions::new().with_allow_http(true))
                .build()
                .map_err(|e| refused(e.to_string()))?,
        ),
        Some(Scheme::Cloud(cloud)) => {
            let (bucket, prefix) = cloud.split(address).map_err(refused)?;
            // A client that cannot be set up lacks a setting: say which the scheme takes.
            let built = |e: zarrs_object_store::object_store::Error| {
                refused(format!("{e} ({})", Scheme::Cloud(cloud).credentials()))
            };
            let store: Arc<dyn ObjectStore> = match cloud {
                Cloud::S3 => Arc::new(
                    AmazonS3Builder::from_env()
                        .with_bucket_name(bucket)
                        .build()
                        .map_err(built)?,
                ),
                Cloud::Gcs => Arc::new(
                    GoogleCloudStorageBuilder::from_env()
                        .with_bucket_name(bucket)
                        .build()
                        .map_err(built)?,
                ),
                Cloud::Azure => Arc::new(
                    MicrosoftAzureBuilder::from_env()
                        .with_container_name(bucket)
                        .build()
                        .map_err(built)?,
                ),
            };
            match prefix {
                "" => store,
                p => Arc::new(PrefixStore::new(store, p)),
            }
        }
    };
    let handle = runtime()
        .map_err(|e| refused(format!("no runtime for network requests: {e}")))?
        .handle()
        .clone();
    let asynchronous = Arc::new(AsyncObjectStore::new(store));
    Ok(Arc::new(AsyncToSyncStorageAdapter::new(
        asynchronous,
        BlockOn(handle),
    )))
}
