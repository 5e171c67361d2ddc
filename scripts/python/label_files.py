"""Label volumes written by nibabel, and what each must give on its image's grid, computed here
with numpy from the affines alone: for LeapView's segmentation tests
(tests/integration/labels.rs).

    python label_files.py OUT
    python label_files.py --counts FILE.nii.gz    prints {"LABEL": VOXELS, …} of FILE (nibabel)
    python label_files.py --long N OUT            writes OUT/long_image.nii.gz and
                                                  OUT/long_labels.nii.gz, N × 48 × 48: a bar
                                                  along x past a GPU's 3D textures, labelled 1
                                                  in its first half, 2 in its second

Writes into OUT, for each case, `<case>_image.nii.gz`, `<case>_labels.nii.gz` and, where LeapView
must accept it, `<case>_expected.u16`: the label each image voxel takes (the label voxel nearest
its centre in patient space, 0 outside), little-endian uint16, x fastest; and `cases.json`
listing the cases with what LeapView is to say.
"""

import json
import os
import sys

import nibabel as nib
import numpy as np


def expected(image_shape, image_affine, labels, labels_affine):
    """Nearest-label resampling through the affines (voxel → RAS mm → voxel)."""
    to_labels = np.linalg.inv(labels_affine) @ image_affine
    i, j, k = np.meshgrid(*[np.arange(n) for n in image_shape], indexing="ij")
    v = np.stack([i, j, k, np.ones_like(i)], axis=-1).reshape(-1, 4).T.astype(np.float64)
    u = np.floor((to_labels @ v)[:3] + 0.5).astype(np.int64)
    inside = np.all((u >= 0) & (u < np.array(labels.shape)[:, None]), axis=0)
    out = np.zeros(v.shape[1], dtype=np.uint16)
    out[inside] = labels[u[0, inside], u[1, inside], u[2, inside]]
    # nibabel's arrays are x-slowest in memory order here: reshape, then write x fastest.
    return out.reshape(image_shape).transpose(2, 1, 0).ravel()


def cases():
    rng = np.random.default_rng(41)
    image_shape = (23, 19, 17)
    image_affine = np.diag([1.0, 1.2, 1.5, 1.0])
    image_affine[:3, 3] = [-11.0, -10.0, -12.0]
    image = rng.normal(100, 20, image_shape).astype(np.int16)

    # Labels on a coarser grid, shifted, with a mirrored x axis and swapped y/z axes: every
    # part of the patient-space mapping is exercised. Spacings chosen so that no image voxel
    # centre falls half-way between two label voxels.
    labels_shape = (15, 9, 12)
    labels_affine = np.array(
        [
            [-1.7, 0.0, 0.0, 13.3],
            [0.0, 0.0, 2.3, -9.1],
            [0.0, 1.9, 0.0, -10.2],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )
    labels = rng.integers(0, 7, labels_shape).astype(np.uint8)
    yield {
        "case": "resampled",
        "image": nib.Nifti1Image(image, image_affine),
        "labels": nib.Nifti1Image(labels, labels_affine),
        "expected": expected(image_shape, image_affine, labels, labels_affine),
    }

    # Float labels with whole values (as some tools write them) are labels.
    yield {
        "case": "float_whole",
        "image": nib.Nifti1Image(image, image_affine),
        "labels": nib.Nifti1Image(labels.astype(np.float32) * 1000, labels_affine),
        "expected": expected(image_shape, image_affine, labels.astype(np.uint16) * 1000,
                             labels_affine),
    }

    # Refused: a probability map (not whole numbers), values past 65535, no overlap.
    prob = rng.random(labels_shape).astype(np.float32)
    yield {
        "case": "not_integers",
        "image": nib.Nifti1Image(image, image_affine),
        "labels": nib.Nifti1Image(prob, labels_affine),
        "refused": "whole numbers",
    }
    many = labels.astype(np.uint32) + 65_530
    yield {
        "case": "too_large",
        "image": nib.Nifti1Image(image, image_affine),
        "labels": nib.Nifti1Image(many, labels_affine),
        "refused": "whole numbers 0 … 65535",
    }
    far = labels_affine.copy()
    far[:3, 3] += [500.0, 0.0, 0.0]
    yield {
        "case": "elsewhere",
        "image": nib.Nifti1Image(image, image_affine),
        "labels": nib.Nifti1Image(labels, far),
        "refused": "do not overlap",
    }


def main(out):
    listed = []
    for c in cases():
        name = c["case"]
        for part in ("image", "labels"):
            c[part].set_qform(c[part].affine, code=1)
            c[part].set_sform(c[part].affine, code=1)
            nib.save(c[part], os.path.join(out, f"{name}_{part}.nii.gz"))
        entry = {"case": name, "refused": c.get("refused")}
        if "expected" in c:
            c["expected"].astype("<u2").tofile(os.path.join(out, f"{name}_expected.u16"))
        listed.append(entry)
    with open(os.path.join(out, "cases.json"), "w") as f:
        json.dump(listed, f, indent=1)


def counts(path):
    data = np.asarray(nib.load(path).dataobj)
    values, n = np.unique(data, return_counts=True)
    print(json.dumps({str(int(v)): int(c) for v, c in zip(values, n) if v != 0}))


def long(n, out):
    """A bar along x of n voxels (past a 3D texture's side), its halves labelled 1 and 2."""
    shape = (n, 48, 48)
    i, j, k = np.meshgrid(*[np.arange(s) for s in shape], indexing="ij", sparse=True)
    bar = (j - 23.5) ** 2 + (k - 23.5) ** 2 < 14**2
    image = np.where(bar, 1000, 0).astype(np.int16) + np.zeros(shape, np.int16)
    labels = (np.where(bar & (i < n // 2), 1, 0) + np.where(bar & (i >= n // 2), 2, 0)).astype(
        np.uint16
    )
    for name, data in (("image", image), ("labels", labels)):
        img = nib.Nifti1Image(data, np.eye(4))
        img.set_qform(np.eye(4), code=1)
        img.set_sform(np.eye(4), code=1)
        nib.save(img, os.path.join(out, f"long_{name}.nii.gz"))


if __name__ == "__main__":
    if sys.argv[1] == "--counts":
        counts(sys.argv[2])
    elif sys.argv[1] == "--long":
        long(int(sys.argv[2]), sys.argv[3])
    else:
        main(sys.argv[1])
