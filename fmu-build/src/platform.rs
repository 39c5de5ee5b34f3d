//! The platforms an FMU carries a binary for, and how each binary is built.
//!
//! The host build (`make demo`) is the workspace's own toolchain building for the machine it
//! runs on. The distribution build (`make fmus-all`) builds every platform with one pinned
//! toolchain, so that the three binaries come from the same compiler: Debian's `rustc-web`
//! (`/usr/bin/cargo`, `/usr/bin/rustc`), the standard library compiled from its sources
//! (`-Zbuild-std`, `rust-web-src`), Linux binaries linked by `zig cc` against glibc 2.28's
//! symbols (`cargo zigbuild`; RHEL 8 and Ubuntu 20.04 load them), the Windows DLL by
//! mingw-w64's gcc. Each pinned path can be overridden through the environment (the
//! `CONTOUR_CROSS_*` variables) for another machine's layout.

use std::path::{Path, PathBuf};
use std::process::Command;

/// A platform folder of `binaries/` and the Rust target that builds its library.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Platform {
    /// `binaries/linux64`: x86-64 Linux (glibc).
    Linux64,
    /// `binaries/win64`: x86-64 Windows 10 and later.
    Win64,
    /// `binaries/aarch64-linux`: 64-bit ARM Linux (glibc). FMI 3.0's platform tuple, which
    /// FMI 2.0.4 (section 2.1) allows beside the 2.0 names.
    Aarch64Linux,
    /// `binaries/darwin64`: x86-64 macOS 10.12 and later. Untested: built and linked here
    /// (zig's libSystem stubs, no SDK) but nothing here runs a Mach-O; only on request.
    Darwin64,
    /// `binaries/aarch64-darwin`: Apple silicon, macOS 11 and later. Untested, as Darwin64.
    Aarch64Darwin,
}

/// The lowest glibc the Linux binaries of the distribution build need: (major, minor).
pub const GLIBC_FLOOR: (u32, u32) = (2, 28);

impl Platform {
    /// The platforms of the distribution build (`--platforms all`).
    pub const ALL: [Platform; 3] = [Platform::Linux64, Platform::Win64, Platform::Aarch64Linux];
    /// Built only when named: nothing here can run them.
    pub const UNTESTED: [Platform; 2] = [Platform::Darwin64, Platform::Aarch64Darwin];

    /// The folder under `binaries/` in an FMI 2.0 FMU.
    pub fn folder(self) -> &'static str {
        match self {
            Platform::Linux64 => "linux64",
            Platform::Win64 => "win64",
            Platform::Aarch64Linux => "aarch64-linux",
            Platform::Darwin64 => "darwin64",
            Platform::Aarch64Darwin => "aarch64-darwin",
        }
    }

    /// The folder under `binaries/` in an FMI 3.0 FMU: FMI 3.0's platform tuple
    /// `<arch>-<sys>`, for the same library.
    pub fn fmi3_folder(self) -> &'static str {
        match self {
            Platform::Linux64 => "x86_64-linux",
            Platform::Win64 => "x86_64-windows",
            Platform::Aarch64Linux => "aarch64-linux",
            Platform::Darwin64 => "x86_64-darwin",
            Platform::Aarch64Darwin => "aarch64-darwin",
        }
    }

    /// Parses a folder name as [`Platform::folder`] writes it.
    pub fn from_folder(name: &str) -> Option<Platform> {
        Platform::ALL
            .into_iter()
            .chain(Platform::UNTESTED)
            .find(|p| p.folder() == name)
    }

    /// The Rust target triple.
    pub fn rust_target(self) -> &'static str {
        match self {
            Platform::Linux64 => "x86_64-unknown-linux-gnu",
            Platform::Win64 => "x86_64-pc-windows-gnu",
            Platform::Aarch64Linux => "aarch64-unknown-linux-gnu",
            Platform::Darwin64 => "x86_64-apple-darwin",
            Platform::Aarch64Darwin => "aarch64-apple-darwin",
        }
    }

    /// The extension of the library in the FMU (`<modelIdentifier>.<ext>`).
    pub fn library_extension(self) -> &'static str {
        match self {
            Platform::Win64 => "dll",
            Platform::Linux64 | Platform::Aarch64Linux => "so",
            Platform::Darwin64 | Platform::Aarch64Darwin => "dylib",
        }
    }

    /// The file cargo writes for the `contour_fmu` cdylib on this platform.
    fn cargo_output(self) -> &'static str {
        match self {
            Platform::Win64 => "contour_fmu.dll",
            Platform::Linux64 | Platform::Aarch64Linux => "libcontour_fmu.so",
            Platform::Darwin64 | Platform::Aarch64Darwin => "libcontour_fmu.dylib",
        }
    }

    /// Whether the tests run this platform's binaries here (under Wine or QEMU).
    pub fn tested(self) -> bool {
        !Platform::UNTESTED.contains(&self)
    }

    /// The lowest macOS release a Darwin binary is linked for.
    fn macos_floor(self) -> Option<&'static str> {
        match self {
            Platform::Darwin64 => Some("10.12"),
            Platform::Aarch64Darwin => Some("11.0"),
            _ => None,
        }
    }

    /// The platform this program was built for, when it is one an FMU carries.
    pub fn host() -> Option<Platform> {
        if cfg!(all(target_os = "linux", target_arch = "x86_64")) {
            Some(Platform::Linux64)
        } else if cfg!(all(target_os = "linux", target_arch = "aarch64")) {
            Some(Platform::Aarch64Linux)
        } else if cfg!(all(windows, target_arch = "x86_64")) {
            Some(Platform::Win64)
        } else {
            None
        }
    }
}

/// A built library and the platform it is for.
#[derive(Clone, Debug)]
pub struct Binary {
    pub platform: Platform,
    pub file: PathBuf,
}

fn run(mut command: Command, what: &str) -> Result<(), String> {
    let status = command
        .status()
        .map_err(|e| format!("{what}: cannot run {:?}: {e}", command.get_program()))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("{what} failed ({status})"))
    }
}

fn produced(file: PathBuf) -> Result<PathBuf, String> {
    if file.exists() {
        Ok(file)
    } else {
        Err(format!("the build did not produce {}", file.display()))
    }
}

/// Builds the library for the host with the workspace's cargo (`$CARGO`), into
/// `<target>/release`.
pub fn build_host(root: &Path, target: &Path) -> Result<Binary, String> {
    let platform = Platform::host().ok_or(
        "this machine is none of the platforms an FMU carries (linux64, win64, aarch64-linux)",
    )?;
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut command = Command::new(cargo);
    command
        .args(["build", "--release", "--lib", "-p", "contour-fmu"])
        .current_dir(root);
    run(command, "cargo build")?;
    let file = produced(target.join("release").join(platform.cargo_output()))?;
    Ok(Binary { platform, file })
}

/// A pinned tool: the environment variable overrides the default path.
fn pinned(variable: &str, default: &str) -> PathBuf {
    std::env::var_os(variable).map_or_else(|| PathBuf::from(default), PathBuf::from)
}

/// Where the distribution build of `platform` leaves its binaries:
/// `<target>/cross/<triple>/release`.
pub fn distribution_dir(target: &Path, platform: Platform) -> PathBuf {
    target
        .join("cross")
        .join(platform.rust_target())
        .join("release")
}

/// Builds the library for `platform` with the pinned distribution toolchain, into
/// [`distribution_dir`], and beside it (for the tested platforms) that platform's
/// `contour-cosim` (the native master, which the tests run under Wine and QEMU as the
/// loops' harness).
pub fn build_distribution(
    root: &Path,
    target: &Path,
    platform: Platform,
) -> Result<Binary, String> {
    let cargo = pinned("CONTOUR_CROSS_CARGO", "/usr/bin/cargo");
    let rustc = pinned("CONTOUR_CROSS_RUSTC", "/usr/bin/rustc");
    for tool in [&cargo, &rustc] {
        if !tool.is_file() {
            return Err(format!(
                "{} is missing: the distribution build needs Debian's rustc-web, cargo-web and \
                 rust-web-src (make fmus-all installs them)",
                tool.display()
            ));
        }
    }
    let cross_target = target.join("cross");
    let triple = platform.rust_target();
    let mut command = match platform {
        Platform::Win64 => {
            let mut command = Command::new(&cargo);
            command.arg("build").arg(format!("--target={triple}")).env(
                "CARGO_TARGET_X86_64_PC_WINDOWS_GNU_LINKER",
                pinned("CONTOUR_CROSS_MINGW_GCC", "/usr/bin/x86_64-w64-mingw32-gcc"),
            );
            command
        }
        // Linked by zig: against glibc 2.28's symbols, or macOS's libSystem stubs.
        Platform::Linux64
        | Platform::Aarch64Linux
        | Platform::Darwin64
        | Platform::Aarch64Darwin => {
            // zig is the ziglang package of the project's venv (make cross-toolchain).
            let python = pinned(
                "CARGO_ZIGBUILD_PYTHON_PATH",
                &root.join(".venv/bin/python").to_string_lossy(),
            );
            if !python.is_file() {
                return Err(format!(
                    "{} is missing: the Linux and macOS binaries are linked by zig from the \
                     ziglang package in the project's venv (make cross-toolchain installs it)",
                    python.display()
                ));
            }
            let mut command = Command::new(pinned("CONTOUR_CROSS_ZIGBUILD", "cargo-zigbuild"));
            command
                .arg("zigbuild")
                .env("CARGO", &cargo)
                .env("CARGO_ZIGBUILD_PYTHON_PATH", python);
            match platform.macos_floor() {
                None => {
                    let (major, minor) = GLIBC_FLOOR;
                    command.arg(format!("--target={triple}.{major}.{minor}"));
                }
                Some(floor) => {
                    // zig ignores the linker's export list: hidden visibility leaves the
                    // fmi2 functions (and a few symbols of the linker's own) exported.
                    command
                        .arg(format!("--target={triple}"))
                        .env("MACOSX_DEPLOYMENT_TARGET", floor)
                        .env(
                            "RUSTFLAGS",
                            "-Zdefault-visibility=hidden \
                             -Clink-arg=-Wl,-install_name,@rpath/libcontour_fmu.dylib",
                        );
                }
            }
            command
        }
    };
    command
        .args(["-Zbuild-std=std,panic_unwind", "--release"])
        .args(["-p", "contour-fmu", "--lib"])
        .env("RUSTC", &rustc)
        .env("RUSTC_BOOTSTRAP", "1")
        .env("CARGO_TARGET_DIR", &cross_target)
        // The host toolchain's settings must not leak into the pinned one.
        .env_remove("CARGO_ENCODED_RUSTFLAGS")
        .env_remove("RUSTUP_TOOLCHAIN")
        .current_dir(root);
    if platform.macos_floor().is_none() {
        command.env_remove("RUSTFLAGS");
    }
    if platform.tested() {
        command.args(["-p", "contour-cosim", "--bins"]);
    }
    run(command, &format!("the {} build", platform.folder()))?;
    let file = produced(distribution_dir(target, platform).join(platform.cargo_output()))?;
    Ok(Binary { platform, file })
}
