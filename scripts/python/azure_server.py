"""Serves folders as an Azure Blob Storage container on loopback (Azurite, Microsoft's emulator,
installed by scripts/setup-debian.sh --tests into .node), for the tests of remote OME-Zarr
stores over az:// (tests/integration/remote.rs).

    python azure_server.py CONTAINER FOLDER [FOLDER …]

Starts Azurite's blob service in memory, uploads each FOLDER's files under its name in CONTAINER
with the Azure SDK (azure-storage-blob) and the emulator's well-known account key, prints one
JSON line {"port": PORT} once serving, and serves until its standard input closes. Azurite checks
the requests' shared-key signatures.
"""

import json
import os
import re
import subprocess
import sys

from azure.storage.blob import BlobServiceClient
from served import each_file

HERE = os.path.dirname(os.path.abspath(__file__))
AZURITE = os.path.join(HERE, "..", "..", ".node", "node_modules", ".bin", "azurite-blob")
# The emulator's account, the same in every Azurite (its documentation's development account).
ACCOUNT = "devstoreaccount1"
KEY = ("Eby8vdM02xNOcqFlqUwJPLlmEtlCDXJ1OUzFT50uSRZ6IFsuFq2UVErCz4I6tq/K1SZFPTOtr/KBHBeksoGMGw==")


def main(container, folders):
    if not os.path.exists(AZURITE):
        sys.exit(f"no Azurite at {AZURITE}: run scripts/setup-debian.sh --tests")
    azurite = subprocess.Popen(
        [AZURITE, "--blobHost", "127.0.0.1", "--blobPort", "0", "--inMemoryPersistence",
         "--disableTelemetry", "--skipApiVersionCheck", "--silent"],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
    )
    port = None
    for line in azurite.stdout:
        found = re.search(r"listens on http://127\.0\.0\.1:(\d+)", line)
        if found:
            port = int(found.group(1))
            break
    if port is None:
        sys.exit("Azurite did not start")
    endpoint = f"http://127.0.0.1:{port}/{ACCOUNT}"
    service = BlobServiceClient(account_url=endpoint, credential={"account_name": ACCOUNT,
                                                                   "account_key": KEY})
    blobs = service.create_container(container)
    for path, key in each_file(folders):
        with open(path, "rb") as data:
            blobs.upload_blob(key, data)
    print(json.dumps({"port": port}), flush=True)
    sys.stdin.read()
    azurite.terminate()
    azurite.wait()


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])
