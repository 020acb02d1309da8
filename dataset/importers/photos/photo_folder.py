"""A folder of photos, checked before anything is computed: which files are photos, what
camera took each (for structure from motion's shared intrinsics), and a clear error for
what cannot be used (too few photos, a video, HEIC or raw files).

Photos are the folder's ``.jpg``, ``.jpeg`` and ``.png`` files (any case), sorted by name;
hidden files, sub-folders and other files (sidecars such as ``.xmp``, ``.aae``) are left
alone. Sizes are the upright sizes (after the EXIF orientation).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from PIL import ExifTags, Image, UnidentifiedImageError

PHOTO_SUFFIXES = (".jpg", ".jpeg", ".png")
VIDEO_SUFFIXES = (".mp4", ".mov", ".m4v", ".avi", ".mkv", ".webm", ".mts", ".3gp", ".mpg",
                  ".mpeg", ".wmv")
UNREAD_PHOTO_SUFFIXES = (".heic", ".heif", ".avif", ".dng", ".cr2", ".cr3", ".nef", ".arw",
                         ".raf", ".orf", ".rw2")
"""Photos Pillow does not read as they are: converted to JPEG first."""
MIN_PHOTOS = 3
"""Two photos start a model; a third is the least that checks it."""
FULL_FRAME_WIDTH_MM = 36.0
"""A 35 mm film frame's long side: EXIF ``FocalLengthIn35mmFilm`` is relative to it."""
_SIDEWAYS_ORIENTATIONS = (5, 6, 7, 8)  # EXIF orientations that swap width and height


@dataclass(frozen=True)
class Photo:
    """One photo of the folder: ``path``, its upright size in pixels, the camera that took
    it (``camera``: EXIF make, model and focal length, or ``""``) and the focal length in
    pixels that its EXIF implies (``None`` without ``FocalLengthIn35mmFilm``)."""

    path: Path
    width: int
    height: int
    camera: str
    focal_px: float | None

    @property
    def name(self) -> str:
        """The file's name: the image's name in the scene and in COLMAP."""
        return self.path.name


def list_photos(folder: str | Path) -> tuple[Photo, ...]:
    """The photos of ``folder``, sorted by name (module docstring).

    Raises
    ------
    ValueError
        ``folder`` is a video or no folder, holds a video or a HEIC or raw photo, fewer than
        :data:`MIN_PHOTOS` photos, or a photo whose header cannot be read.
    """
    folder = Path(folder)
    if folder.suffix.lower() in VIDEO_SUFFIXES:
        raise ValueError(f"{folder} is a video: extract frames into a folder first (e.g. "
                         f"`ffmpeg -i {folder.name} -vf fps=2 frames/%04d.jpg`) and give that "
                         "folder to --photos")
    if not folder.is_dir():
        raise ValueError(f"{folder} is not a folder of photos (give --photos a folder of "
                         f"JPEG or PNG photos)")
    files = sorted(p for p in folder.iterdir() if p.is_file() and not p.name.startswith("."))
    videos = [p.name for p in files if p.suffix.lower() in VIDEO_SUFFIXES]
    if videos:
        raise ValueError(f"{folder} holds videos ({', '.join(videos[:3])}): extract frames "
                         "first (e.g. `ffmpeg -i VIDEO -vf fps=2 frames/%04d.jpg`) and give the "
                         "frames' folder to --photos, without the videos")
    unread = [p.name for p in files if p.suffix.lower() in UNREAD_PHOTO_SUFFIXES]
    if unread:
        raise ValueError(f"{folder} holds photos in a format that is not read here "
                         f"({', '.join(unread[:3])}): convert them to JPEG first")
    photos = tuple(_read_header(p) for p in files if p.suffix.lower() in PHOTO_SUFFIXES)
    if len(photos) < MIN_PHOTOS:
        raise ValueError(f"{folder} holds {len(photos)} photos (JPEG or PNG); structure from "
                         f"motion needs at least {MIN_PHOTOS}, and a building wants dozens: "
                         "walk round it, each part in three photos or more")
    return photos


def camera_groups(photos: tuple[Photo, ...]) -> dict[tuple, list[Photo]]:
    """The photos grouped by the camera that took them, in order of first appearance: one
    group per (camera, upright size, focal length in pixels). Each group shares one set of
    intrinsics in structure from motion; photos of different cameras or sizes get their own."""
    groups: dict[tuple, list[Photo]] = {}
    for photo in photos:
        groups.setdefault((photo.camera, photo.width, photo.height, photo.focal_px),
                          []).append(photo)
    return groups


def _read_header(path: Path) -> Photo:
    try:
        with Image.open(path) as img:
            width, height = img.size
            exif = img.getexif()
    except (UnidentifiedImageError, OSError, SyntaxError, ValueError) as exc:
        raise ValueError(f"{path}: not an image Pillow can read ({exc}); copy the file again "
                         "or re-save it as JPEG") from exc
    if exif.get(ExifTags.Base.Orientation) in _SIDEWAYS_ORIENTATIONS:
        width, height = height, width
    details = exif.get_ifd(ExifTags.IFD.Exif)
    focal_mm = details.get(ExifTags.Base.FocalLength)
    focal_35 = details.get(ExifTags.Base.FocalLengthIn35mmFilm)
    camera = " ".join(str(v).strip() for v in (exif.get(ExifTags.Base.Make),
                                                exif.get(ExifTags.Base.Model),
                                                focal_mm) if v)
    focal_px = (float(focal_35) / FULL_FRAME_WIDTH_MM * max(width, height)
                if focal_35 else None)
    return Photo(path, width, height, camera, focal_px)
