//! The addresses a remote store may have, by scheme: what each names and which credentials it
//! takes (kept apart from `remote`, which is built only with the `remote` feature, so that a
//! build without it still knows an address from a path).

/// How an address is read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Scheme {
    /// `http://` or `https://`: plain range requests, no credentials.
    Http,
    /// An object store whose address names a bucket (or container) and a path in it.
    Cloud(Cloud),
}

/// The object stores whose addresses name a bucket: `SCHEME://BUCKET/PATH`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Cloud {
    /// Amazon S3 or any S3-compatible server.
    S3,
    /// Google Cloud Storage.
    Gcs,
    /// Azure Blob Storage.
    Azure,
}

/// Every scheme prefix taken, lower case, with what it names.
const PREFIXES: [(&str, Scheme); 7] = [
    ("http://", Scheme::Http),
    ("https://", Scheme::Http),
    ("s3://", Scheme::Cloud(Cloud::S3)),
    ("gs://", Scheme::Cloud(Cloud::Gcs)),
    ("gcs://", Scheme::Cloud(Cloud::Gcs)),
    ("az://", Scheme::Cloud(Cloud::Azure)),
    ("azure://", Scheme::Cloud(Cloud::Azure)),
];

impl Scheme {
    /// The scheme of `address`; `None` for a path.
    pub(crate) fn of(address: &str) -> Option<Self> {
        PREFIXES
            .iter()
            .find(|(prefix, _)| {
                address
                    .get(..prefix.len())
                    .is_some_and(|head| head.eq_ignore_ascii_case(prefix))
            })
            .map(|&(_, scheme)| scheme)
    }

    /// Which credentials this scheme takes, for a refusal.
    pub(crate) fn credentials(self) -> &'static str {
        match self {
            Self::Http => {
                "an http(s):// address is read without credentials: give a public address, or \
                 the store's s3://, gs:// or az:// address"
            }
            Self::Cloud(Cloud::S3) => {
                "for s3://, AWS_ACCESS_KEY_ID and AWS_SECRET_ACCESS_KEY; AWS_SKIP_SIGNATURE=true \
                 for a public bucket"
            }
            Self::Cloud(Cloud::Gcs) => {
                "for gs://, GOOGLE_SERVICE_ACCOUNT (a key file) or GOOGLE_APPLICATION_CREDENTIALS; \
                 GOOGLE_SKIP_SIGNATURE=true for a public bucket"
            }
            Self::Cloud(Cloud::Azure) => {
                "for az://, AZURE_STORAGE_ACCOUNT_NAME with AZURE_STORAGE_ACCOUNT_KEY or \
                 AZURE_STORAGE_SAS_KEY; AZURE_SKIP_SIGNATURE=true for a public container"
            }
        }
    }
}

impl Cloud {
    /// What the address's first part names.
    fn bucket(self) -> &'static str {
        match self {
            Self::Azure => "container",
            Self::S3 | Self::Gcs => "bucket",
        }
    }

    /// The scheme as written in the address's form.
    fn scheme(self) -> &'static str {
        match self {
            Self::S3 => "s3://",
            Self::Gcs => "gs://",
            Self::Azure => "az://",
        }
    }

    /// The bucket and the path in it (without slashes at its ends) that `address` names; the
    /// reason where it names no bucket.
    pub(crate) fn split(self, address: &str) -> Result<(&str, &str), String> {
        let rest = address.find("://").map_or(address, |i| &address[i + 3..]);
        let (bucket, path) = rest.split_once('/').unwrap_or((rest, ""));
        if bucket.is_empty() {
            return Err(format!(
                "the address names no {0}: {1}{0}/PATH",
                self.bucket(),
                self.scheme()
            ));
        }
        Ok((bucket, path.trim_matches('/')))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schemes_are_told_apart_in_any_case_and_paths_have_none() {
        assert_eq!(Scheme::of("HTTPS://x/y"), Some(Scheme::Http));
        assert_eq!(Scheme::of("s3://b/k"), Some(Scheme::Cloud(Cloud::S3)));
        assert_eq!(Scheme::of("Gs://b/k"), Some(Scheme::Cloud(Cloud::Gcs)));
        assert_eq!(Scheme::of("az://c/k"), Some(Scheme::Cloud(Cloud::Azure)));
        assert_eq!(Scheme::of("azure://c"), Some(Scheme::Cloud(Cloud::Azure)));
        assert_eq!(Scheme::of("/data/s3://x"), None);
        assert_eq!(Scheme::of("gs:/b"), None);
        assert_eq!(Scheme::of("é"), None);
    }

    #[test]
    fn an_address_splits_into_its_bucket_and_path() {
        assert_eq!(
            Cloud::S3.split("s3://bkt/a/b.zarr/"),
            Ok(("bkt", "a/b.zarr"))
        );
        assert_eq!(Cloud::Gcs.split("gs://bkt"), Ok(("bkt", "")));
        assert_eq!(Cloud::Azure.split("az://c//x"), Ok(("c", "x")));
        let e = Cloud::Azure.split("az:///x").expect_err("no container");
        assert!(e.contains("az://container/PATH"), "{e}");
    }
}
