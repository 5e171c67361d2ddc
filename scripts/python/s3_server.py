"""Serves folders as an S3-compatible object store on loopback (moto's server), for the tests of
remote OME-Zarr stores (tests/integration/remote.rs): the same server answers S3 requests
(s3://BUCKET/NAME with AWS_ENDPOINT_URL) and plain HTTP GETs with ranges
(http://127.0.0.1:PORT/BUCKET/NAME/KEY, path style).

    python s3_server.py [--auth] BUCKET FOLDER [FOLDER …]

Uploads each FOLDER's files under its name in BUCKET (a public-read bucket, so that plain HTTP
reads it too), prints one JSON line {"port": PORT} once serving, and serves until its standard
input closes. With --auth the server checks credentials (moto's IAM): it makes a user allowed
everything, uploads with its key, and prints {"port": PORT, "key": ID, "secret": SECRET}.
"""

import json
import os
import sys

AUTH = "--auth" in sys.argv
if AUTH:
    # Requests before this many go unchecked: the user, its policy and its key (read by moto
    # when imported).
    os.environ["INITIAL_NO_AUTH_ACTION_COUNT"] = "3"

import boto3  # noqa: E402
from moto.server import ThreadedMotoServer  # noqa: E402
from served import each_file  # noqa: E402


def main(bucket, folders):
    server = ThreadedMotoServer(ip_address="127.0.0.1", port=0, verbose=False)
    server.start()
    host, port = server.get_host_and_port()
    endpoint = f"http://{host}:{port}"
    access = {"AccessKeyId": "testing", "SecretAccessKey": "testing"}
    if AUTH:
        iam = boto3.client("iam", endpoint_url=endpoint, aws_access_key_id="testing",
                           aws_secret_access_key="testing", region_name="us-east-1")
        iam.create_user(UserName="reader")
        everything = {"Version": "2012-10-17",
                      "Statement": [{"Effect": "Allow", "Action": "*", "Resource": "*"}]}
        iam.put_user_policy(UserName="reader", PolicyName="everything",
                            PolicyDocument=json.dumps(everything))
        access = iam.create_access_key(UserName="reader")["AccessKey"]
    s3 = boto3.client(
        "s3",
        endpoint_url=endpoint,
        aws_access_key_id=access["AccessKeyId"],
        aws_secret_access_key=access["SecretAccessKey"],
        region_name="us-east-1",
    )
    s3.create_bucket(Bucket=bucket, ACL="public-read")
    for path, key in each_file(folders):
        s3.upload_file(path, bucket, key, ExtraArgs={"ACL": "public-read"})
    said = {"port": port}
    if AUTH:
        said.update(key=access["AccessKeyId"], secret=access["SecretAccessKey"])
    print(json.dumps(said), flush=True)
    sys.stdin.read()
    server.stop()


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--auth"]
    main(args[0], args[1:])
