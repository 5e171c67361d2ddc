"""Serves a folder over plain HTTP with range requests on loopback (rangehttpserver's handler on
a threading server), for the tests of remote OME-Zarr stores (tests/integration/remote.rs).

    python http_server.py FOLDER

Prints one JSON line {"port": PORT} once serving, and serves until its standard input closes.
"""

import functools
import json
import sys
import threading
from http.server import ThreadingHTTPServer

from RangeHTTPServer import RangeRequestHandler


class Quiet(RangeRequestHandler):
    def log_message(self, *args):
        pass


def main(folder):
    handler = functools.partial(Quiet, directory=folder)
    server = ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    print(json.dumps({"port": server.server_address[1]}), flush=True)
    sys.stdin.read()
    server.shutdown()


if __name__ == "__main__":
    main(sys.argv[1])
