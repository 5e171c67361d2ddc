"""Serves folders as an S3-compatible object store on loopback (moto's server), for the tests of
remote OME-Zarr stores (tests/integration/remote.rs): the same server answers S3 requests
(s3://BUCKET/NAME with AWS_ENDPOINT_URL) and plain HTTP GETs with ranges
(http://127.0.0.1:PORT/BUCKET/NAME/KEY, path style).

    python s3_server.py BUCKET FOLDER [FOLDER …]

Uploads each FOLDER's files under its name in BUCKET (a public-read bucket, so that plain HTTP
reads it too), prints one JSON line {"port": PORT} once serving, and serves until its standard
input closes.
"""

import json
import os
import sys

import boto3
from moto.server import ThreadedMotoServer


def main(bucket, folders):
    server = ThreadedMotoServer(ip_address="127.0.0.1", port=0, verbose=False)
    server.start()
    host, port = server.get_host_and_port()
    s3 = boto3.client(
        "s3",
        endpoint_url=f"http://{host}:{port}",
        aws_access_key_id="testing",
        aws_secret_access_key="testing",
        region_name="us-east-1",
    )
    s3.create_bucket(Bucket=bucket, ACL="public-read")
    for folder in folders:
        name = os.path.basename(os.path.normpath(folder))
        for root, _, files in os.walk(folder):
            for f in files:
                path = os.path.join(root, f)
                key = name + "/" + os.path.relpath(path, folder).replace(os.sep, "/")
                s3.upload_file(path, bucket, key, ExtraArgs={"ACL": "public-read"})
    print(json.dumps({"port": port}), flush=True)
    sys.stdin.read()
    server.stop()


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])
