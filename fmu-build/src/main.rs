//! `cargo run --release -p fmu-build [-- --bless] [--platforms host|all|LIST] [--out DIR]
//! [--resource MODEL=FILE]…`: builds the library in release mode, for this machine or for
//! every platform (`platform.rs`), checks each binary (`binary_check.rs`) and writes one
//! `.fmu` per model, unit system and FMI standard carrying them all: FMI 2.0 in mm to
//! `target/fmu/` (or DIR), in SI to `target/fmu-si/` (DIR-si), FMI 3.0 in mm to
//! `target/fmu3/` (DIR3) and in SI to `target/fmu3-si/` (DIR3-si); one library serves all.
//! `--bless` rewrites the committed `modelDescription/[fmi3/][si/]<Model>.xml` files from
//! the code; each `--resource` puts FILE into MODEL's `resources/` folder in every build.
//! PathInterpolator5X always carries the example CL part `examples/cl/blade.cl` as
//! `resources/blade.cl`. The loops' SSP files (`python/contour_fmu/loops/*.ssd`, and
//! `loops/si/` for the SI build) go beside the FMI 2.0 FMUs, where their components' sources
//! are (SSP 1.0 knows FMI 1.0 and 2.0 only).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use contour_fmu::fmi::{FMI2_CO_SIMULATION, FMI3_FUNCTIONS};
use contour_fmu::framework::interface::{Interface, UnitSystem};
use contour_fmu::models;
use fmu_build::model_description;
use fmu_build::package::{self, Binaries, Resource};
use fmu_build::platform::{self, Platform, GLIBC_FLOOR};
use fmu_build::standard::Standard;

const USAGE: &str = "usage: fmu-build [--bless] [--platforms host|all|LIST] [--out DIR] [--resource MODEL=FILE]...\n\
  builds the contour-fmu library (release) and packages, from that one library,\n\
  FMI 2.0: target/fmu/<Model>.fmu (mm) and target/fmu-si/<Model>.fmu (SI),\n\
  FMI 3.0: target/fmu3/<Model>.fmu (mm) and target/fmu3-si/<Model>.fmu (SI)\n\
  --bless                rewrite modelDescription/<Model>.xml (FMI 2.0) and\n\
                         modelDescription/fmi3/<Model>.xml (FMI 3.0), si/ beside each,\n\
                         from the variable tables\n\
  --platforms host       (default) one binary, built for this machine by the workspace's cargo\n\
  --platforms all        linux64, win64 and aarch64-linux (FMI 3.0: x86_64-linux,\n\
                         x86_64-windows, aarch64-linux), built by the pinned distribution\n\
                         toolchain (make fmus-all installs it; docs/usage.md)\n\
  --platforms LIST       some of them, comma-separated (e.g. linux64,win64); also the\n\
                         untested darwin64 and aarch64-darwin (linked, never run here)\n\
  --out DIR              write the .fmu files to DIR, DIR-si, DIR3 and DIR3-si instead of\n\
                         <target>/fmu, <target>/fmu-si, <target>/fmu3 and <target>/fmu3-si\n\
  --resource MODEL=FILE  put FILE into MODEL's resources/ folder under its own name\n\
                         (repeatable; e.g. PathInterpolator2D=part.json, then set the\n\
                         FMU's parameter path = \"part.json\")";

/// The APT CL part every PathInterpolator5X carries in its resources.
const EXAMPLE_CL_PART: &str = "examples/cl/blade.cl";
/// The loops as SSP system structures, for engines that read SSP (libcosim).
const LOOPS: &str = "python/contour_fmu/loops";

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("fmu-build lives in the workspace")
        .to_path_buf()
}

fn target_dir(root: &Path) -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| root.join("target"), PathBuf::from)
}

/// What `--platforms` asks for: the host build, or the distribution build of some platforms.
#[derive(Debug, PartialEq, Eq)]
enum Platforms {
    Host,
    Distribution(Vec<Platform>),
}

impl Platforms {
    fn parse(text: &str) -> Result<Platforms, String> {
        match text {
            "host" => return Ok(Platforms::Host),
            "all" => return Ok(Platforms::Distribution(Platform::ALL.to_vec())),
            _ => {}
        }
        let mut chosen = Vec::new();
        for name in text.split(',') {
            let platform = Platform::from_folder(name.trim()).ok_or_else(|| {
                format!(
                    "--platforms: unknown platform '{name}' (host, all, or some of {}; \
                     untested, only when named: {})",
                    Platform::ALL.map(Platform::folder).join(", "),
                    Platform::UNTESTED.map(Platform::folder).join(", ")
                )
            })?;
            if !chosen.contains(&platform) {
                chosen.push(platform);
            }
        }
        Ok(Platforms::Distribution(chosen))
    }
}

/// Builds the libraries `platforms` asks for and checks them; a distribution build's Linux
/// binaries must need no glibc newer than [`GLIBC_FLOOR`].
fn build_binaries(root: &Path, platforms: &Platforms) -> Result<Binaries, String> {
    let target = target_dir(root);
    let built = match platforms {
        Platforms::Host => vec![platform::build_host(root, &target)?],
        Platforms::Distribution(list) => list
            .iter()
            .map(|p| platform::build_distribution(root, &target, *p))
            .collect::<Result<Vec<_>, _>>()?,
    };
    let binaries = Binaries::load(&built)?;
    for (platform, checked) in binaries.platforms() {
        let glibc = checked
            .glibc
            .map(|(a, b)| format!(", needs glibc {a}.{b}"))
            .unwrap_or_default();
        let untested = if platform.tested() {
            ""
        } else {
            " (UNTESTED: nothing here runs it)"
        };
        println!(
            "binaries/{}: build {}, exports the {} fmi2 and {} fmi3 functions{glibc}{untested}",
            platform.folder(),
            checked.build_id,
            FMI2_CO_SIMULATION.len(),
            FMI3_FUNCTIONS.len()
        );
        if let (Platforms::Distribution(_), Some(needed)) = (platforms, checked.glibc) {
            if needed > GLIBC_FLOOR {
                return Err(format!(
                    "the {} binary needs glibc {}.{}, newer than {}.{}",
                    platform.folder(),
                    needed.0,
                    needed.1,
                    GLIBC_FLOOR.0,
                    GLIBC_FLOOR.1
                ));
            }
        }
    }
    Ok(binaries)
}

fn run(args: &[String]) -> Result<(), String> {
    let mut bless = false;
    let mut platforms = Platforms::Host;
    let mut out = None;
    let mut resources = Vec::new();
    let mut rest = args.iter();
    while let Some(arg) = rest.next() {
        match arg.as_str() {
            "--bless" => bless = true,
            "--platforms" => {
                platforms = Platforms::parse(rest.next().ok_or("--platforms needs a value")?)?
            }
            "--out" => out = Some(PathBuf::from(rest.next().ok_or("--out needs a directory")?)),
            "--resource" => {
                let spec = rest.next().ok_or("--resource needs MODEL=FILE")?;
                resources.push(Resource::parse(spec)?);
            }
            "-h" | "--help" => {
                println!("{USAGE}");
                return Ok(());
            }
            other => match other.strip_prefix("--resource=") {
                Some(spec) => resources.push(Resource::parse(spec)?),
                None => return Err(format!("unknown argument '{other}'\n{USAGE}")),
            },
        }
    }
    let root = workspace_root();
    // The example CL part ships with PathInterpolator5X (path = "blade.cl"), unless a
    // resource of that name replaces it.
    let example = Resource::parse(&format!(
        "PathInterpolator5X={}",
        root.join(EXAMPLE_CL_PART).display()
    ))?;
    if !resources
        .iter()
        .any(|r| r.model == example.model && r.name == example.name)
    {
        resources.push(example);
    }
    // Refused before the (slow) build, so a typo costs nothing.
    package::check_unique(&resources)?;
    let out = out.unwrap_or_else(|| target_dir(&root).join("fmu"));

    let mut stale = Vec::new();
    for (standard, interface) in packaged() {
        let xml = standard.model_description(interface);
        let committed = model_description::committed(&root, interface, standard);
        if bless {
            let committed_dir = committed.parent().expect("a file in a folder");
            std::fs::create_dir_all(committed_dir).map_err(|e| e.to_string())?;
            std::fs::write(&committed, &xml)
                .map_err(|e| format!("cannot write {}: {e}", committed.display()))?;
            println!("blessed {}", committed.display());
        } else if std::fs::read_to_string(&committed).ok().as_deref() != Some(xml.as_str()) {
            stale.push(committed.display().to_string());
        }
    }

    let binaries = build_binaries(&root, &platforms)?;
    for (standard, interface) in packaged() {
        let folder = standard.output_folder(&out, interface.units);
        let fmu =
            package::write_fmu_with_resources(interface, standard, &binaries, &folder, &resources)?;
        println!("wrote {}", fmu.display());
        for r in resources
            .iter()
            .filter(|r| r.model == interface.model.identifier)
        {
            println!("  resources/{} <- {}", r.name, r.source.display());
        }
    }
    copy_loops(
        &root.join(LOOPS),
        &Standard::Fmi2.output_folder(&out, UnitSystem::Millimetre),
    )?;
    copy_loops(
        &root.join(LOOPS).join("si"),
        &Standard::Fmi2.output_folder(&out, UnitSystem::Si),
    )?;
    if !stale.is_empty() {
        eprintln!(
            "warning: the committed model descriptions differ from the code (the FMUs use the code's): {}\n\
             run `cargo run --release -p fmu-build -- --bless` and commit the result",
            stale.join(", ")
        );
    }
    Ok(())
}

/// Copies every `.ssd` of `from` into `to` (an SSD's start values are in the units of the
/// build beside which it goes: loops/ in mm, loops/si/ in m).
fn copy_loops(from: &Path, to: &Path) -> Result<(), String> {
    let entries = std::fs::read_dir(from).map_err(|e| format!("{}: {e}", from.display()))?;
    for entry in entries {
        let path = entry.map_err(|e| e.to_string())?.path();
        if path.extension().is_some_and(|e| e == "ssd") {
            let target = to.join(path.file_name().expect("a file"));
            std::fs::copy(&path, &target).map_err(|e| {
                format!(
                    "cannot copy {} to {}: {e}",
                    path.display(),
                    target.display()
                )
            })?;
            println!("wrote {}", target.display());
        }
    }
    Ok(())
}

/// The FMUs packaged: both standards of both unit systems of every model [`models::all`]
/// lists, FMI 2.0 first.
fn packaged() -> impl Iterator<Item = (Standard, &'static Interface)> {
    Standard::ALL.into_iter().flat_map(|standard| {
        models::interfaces()
            .iter()
            .filter(|i| models::all().iter().any(|m| std::ptr::eq(*m, i.model)))
            .map(move |i| (standard, i))
    })
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("fmu-build: {message}");
            ExitCode::FAILURE
        }
    }
}
