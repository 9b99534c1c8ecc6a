"""A PEP 517 build backend with nothing but the standard library, so
`pip install ./python` works offline (pip's isolated build environment
needs no setuptools or wheel from an index).

It packs `motion_supervisor_client/` (its .py files and layout.json) into a
pure-Python wheel with the metadata and console scripts of pyproject.toml's
[project] table, and an sdist of the same files.
"""

import base64
import hashlib
import io
import os
import tarfile
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = "motion_supervisor_client"
SDIST_FILES = ("pyproject.toml", "_build/wheel_backend.py")


def _project() -> dict:
    text = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    try:
        import tomllib
    except ImportError:  # Python < 3.11: the few flat keys this file uses
        return _flat_toml(text)
    return tomllib.loads(text)["project"]


def _flat_toml(text: str) -> dict:
    import ast

    project, table = {}, None
    for line in text.splitlines():
        line = line.strip()
        if line.startswith("["):
            table = line.strip("[]")
            if table == "project.scripts":
                project["scripts"] = {}
        elif "=" in line and not line.startswith("#") and table in ("project", "project.scripts"):
            key, value = (s.strip() for s in line.split("=", 1))
            value = ast.literal_eval(value)
            (project if table == "project" else project["scripts"])[key.strip('"')] = value
    return project


def _files():
    """(path in the archive, bytes) of the package."""
    for p in sorted((ROOT / PACKAGE).iterdir()):
        if p.suffix in (".py", ".json") and p.is_file():
            yield f"{PACKAGE}/{p.name}", p.read_bytes()


def _dist(project) -> str:
    return f"{project['name'].replace('-', '_')}-{project['version']}"


def _metadata(project) -> bytes:
    lines = [
        "Metadata-Version: 2.1",
        f"Name: {project['name']}",
        f"Version: {project['version']}",
        f"Summary: {project.get('description', '')}",
        f"License: {project.get('license', '')}",
        f"Requires-Python: {project.get('requires-python', '>=3')}",
    ]
    lines += [f"Requires-Dist: {d}" for d in project.get("dependencies", [])]
    return ("\n".join(lines) + "\n").encode()


def _dist_info(project) -> dict:
    scripts = project.get("scripts", {})
    entry = "[console_scripts]\n" + "".join(f"{k} = {v}\n" for k, v in scripts.items())
    wheel = "Wheel-Version: 1.0\nGenerator: motion wheel_backend\nRoot-Is-Purelib: true\nTag: py3-none-any\n"
    return {"METADATA": _metadata(project), "WHEEL": wheel.encode(), "entry_points.txt": entry.encode()}


def _record_line(name: str, data: bytes) -> str:
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{name},sha256={digest},{len(data)}\n"


def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_sdist(config_settings=None):
    return []


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    project = _project()
    dist = _dist(project)
    name = f"{dist}-py3-none-any.whl"
    record = ""
    with zipfile.ZipFile(os.path.join(wheel_directory, name), "w", zipfile.ZIP_DEFLATED) as z:
        entries = list(_files()) + [(f"{dist}.dist-info/{k}", v) for k, v in _dist_info(project).items()]
        for arcname, data in entries:
            z.writestr(arcname, data)
            record += _record_line(arcname, data)
        record += f"{dist}.dist-info/RECORD,,\n"
        z.writestr(f"{dist}.dist-info/RECORD", record)
    return name


def build_sdist(sdist_directory, config_settings=None):
    project = _project()
    dist = _dist(project)
    name = f"{dist}.tar.gz"
    with tarfile.open(os.path.join(sdist_directory, name), "w:gz") as t:
        files = [(f, (ROOT / f).read_bytes()) for f in SDIST_FILES] + list(_files())
        files.append(("PKG-INFO", _metadata(project)))
        for arcname, data in files:
            info = tarfile.TarInfo(f"{dist}/{arcname}")
            info.size = len(data)
            info.mode = 0o644
            t.addfile(info, io.BytesIO(data))
    return name
