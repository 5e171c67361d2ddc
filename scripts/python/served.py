"""What the loopback store servers (s3_server.py, gcs_server.py, azure_server.py) share: the
files of the folders they serve, each under its folder's name."""

import os


def each_file(folders):
    """(path, key) of every file below each folder, the key `FOLDER_NAME/RELATIVE/PATH`."""
    for folder in folders:
        name = os.path.basename(os.path.normpath(folder))
        for root, _, files in os.walk(folder):
            for f in files:
                path = os.path.join(root, f)
                yield path, name + "/" + os.path.relpath(path, folder).replace(os.sep, "/")
