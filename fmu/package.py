"""Package vehsim's FMI 2.0 co-simulation FMU: modelDescription.xml (read from the built
library itself, so the variables cannot disagree with the code), the shared library under
binaries/<platform>/vehsim.<ext>, and the project's manoeuvre specs, vehicles and tyres under
resources/ (a relative `spec` or `vehicle` parameter is read from there).

    python3 fmu/package.py --lib target/release/libvehsim_fmu.so --out target/vehsim.fmu

Called by fmu/build.sh (docs/fmu.md). The archive is deterministic: sorted entries, fixed
timestamps. Standard library only.
"""

import argparse
import ctypes
import platform
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def fmi_platform() -> tuple:
    """(FMI 2.0 binaries folder, shared-library extension) for this machine."""
    bits = "64" if sys.maxsize > 2**32 else "32"
    system = platform.system()
    if system == "Linux":
        return f"linux{bits}", "so"
    if system == "Darwin":
        return f"darwin{bits}", "dylib"
    if system == "Windows":
        return f"win{bits}", "dll"
    raise SystemExit(f"package.py: no FMI 2.0 platform name for {system}")


def resources():
    """(archive name, file) of every spec, vehicle and tyre file the FMU carries."""
    files = sorted((ROOT / "maneuvers").glob("*.toml"))
    files += sorted(p for p in (ROOT / "vehicles").rglob("*") if p.is_file())
    return [("resources/" + p.relative_to(ROOT).as_posix(), p) for p in files]


def add(z: zipfile.ZipFile, name: str, data: bytes, mode: int = 0o644) -> None:
    info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
    info.compress_type = zipfile.ZIP_DEFLATED
    info.external_attr = (0o100000 | mode) << 16
    z.writestr(info, data)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lib", required=True, type=Path, help="the built cdylib (libvehsim_fmu.so)")
    ap.add_argument("--out", required=True, type=Path, help="the .fmu to write")
    args = ap.parse_args()
    if not args.lib.is_file():
        print(f"package.py: {args.lib}: file not found (build it first: bash fmu/build.sh)", file=sys.stderr)
        return 2
    lib = ctypes.CDLL(str(args.lib.resolve()))
    lib.vehsim_fmu_model_description.restype = ctypes.c_char_p
    xml = lib.vehsim_fmu_model_description()
    folder, ext = fmi_platform()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    tmp = args.out.with_name(args.out.name + ".tmp")
    with zipfile.ZipFile(tmp, "w") as z:
        add(z, "modelDescription.xml", xml)
        add(z, f"binaries/{folder}/vehsim.{ext}", args.lib.read_bytes(), 0o755)
        for name, path in resources():
            add(z, name, path.read_bytes())
    tmp.replace(args.out)
    print(f"wrote {args.out} ({args.out.stat().st_size / 1e6:.1f} MB)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
