"""Serves folders as a Google Cloud Storage bucket on loopback (gcp-storage-emulator's server),
for the tests of remote OME-Zarr stores over gs:// (tests/integration/remote.rs).

    python gcs_server.py BUCKET FOLDER [FOLDER …]

Uploads each FOLDER's files under its name in BUCKET (through the emulator's XML API, as
`gsutil` does), prints one JSON line {"port": PORT} once serving, and serves until its standard
input closes. The emulator checks no credentials.
"""

import json
import sys
import urllib.request

from datetime import datetime
from email.utils import format_datetime

from gcp_storage_emulator import server as emulator
from gcp_storage_emulator.handlers import objects
from gcp_storage_emulator.server import create_server
from served import each_file


class _HeadersOnly:
    """The handler's output passing its first write (the status line and headers, flushed at
    once) and dropping the body after it."""

    def __init__(self, out):
        self.out, self.passed = out, False

    def write(self, data):
        if self.passed:
            return len(data)
        self.passed = True
        return self.out.write(data)

    def flush(self):
        self.out.flush()


def _head(handler):
    # The emulator answers no HEAD, which object_store's client sends for an object's size: it is
    # answered as GCS does, the GET's status and headers without the body.
    handler.command, handler.wfile = "GET", _HeadersOnly(handler.wfile)
    handler.do_GET()


def _download(download):
    # GCS's XML API answers a read with the object's ETag and Last-Modified, which object_store's
    # client requires; the emulator sends neither, so they are added from the object's record.
    def answer(request, response, storage, *args, **kwargs):
        try:
            obj = storage.get_file_obj(request.params["bucket_name"], request.params["object_id"])
            response["ETag"] = '"{}"'.format(obj["etag"])
            updated = datetime.fromisoformat(obj["updated"].replace("Z", "+00:00"))
            response["Last-Modified"] = format_datetime(updated, usegmt=True)
        except Exception:  # noqa: BLE001 - no such object: the download answers 404 itself
            pass
        return download(request, response, storage, *args, **kwargs)

    return answer


emulator.RequestHandler.do_HEAD = _head
emulator.HANDLERS = tuple(
    (route, {m: _download(h) if h is objects.download else h for m, h in methods.items()})
    for route, methods in emulator.HANDLERS
)


def main(bucket, folders):
    server = create_server("127.0.0.1", 0, in_memory=True, default_bucket=bucket)
    server.start()
    port = server._api._httpd.server_address[1]
    for path, key in each_file(folders):
        with open(path, "rb") as data:
            request = urllib.request.Request(
                f"http://127.0.0.1:{port}/{bucket}/{key}", data=data.read(), method="PUT"
            )
        urllib.request.urlopen(request).close()
    print(json.dumps({"port": port}), flush=True)
    sys.stdin.read()
    server.stop()


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])
