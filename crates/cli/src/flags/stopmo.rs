//! The command-line flags of the stopmo jobs, declared in the CLI beside the stopmo crate's
//! options they fill: [`SegmentOptionsArgs`] → [`SegmentJobOptions`] (`stopmo segment` and
//! `stopmo run`), [`LibraryOptionsArgs`] → [`LibraryJobOptions`] (`stopmo library` and
//! `stopmo run`), with the files the flags name (`--segmentation`, `--saliency`, `--fixed`)
//! read through `tkio`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};
use glam::Vec3;

use ::stopmo::library::{
    Method, PlugOptions, SolveOptions, DEFAULT_LAMBDA, DEFAULT_PLUG_CLEARANCE_MM,
    DEFAULT_PLUG_LENGTH_MM, DEFAULT_PLUG_RADIUS_MM, DEFAULT_PRINT_HEIGHT_MM, DEFAULT_RESTARTS,
    DEFAULT_SEED, DEFAULT_THICKNESS_MM,
};
use ::stopmo::segment::{PartSpec, Seed, SegmentOptions, DEFAULT_GAMMA};
use ::stopmo::{LibraryJobOptions, PieceCount, SegmentJobOptions};

use super::FlagError;

type Result<T, E = FlagError> = std::result::Result<T, E>;

macro_rules! bail {
    ($($t:tt)*) => {
        return Err(FlagError::Flag(format!($($t)*)))
    };
}

/// Names the flag or file an error is about.
trait At<T> {
    fn with_context(self, at: impl FnOnce() -> String) -> Result<T>;
}

impl<T, E: std::error::Error + Send + Sync + 'static> At<T> for std::result::Result<T, E> {
    fn with_context(self, at: impl FnOnce() -> String) -> Result<T> {
        self.map_err(|e| FlagError::At {
            at: at(),
            source: Box::new(e),
        })
    }
}

impl<T> At<T> for Option<T> {
    fn with_context(self, at: impl FnOnce() -> String) -> Result<T> {
        self.ok_or_else(|| FlagError::Flag(at()))
    }
}

/// Segmentation options shared by `stopmo segment` and `stopmo run`.
#[derive(Debug, Args)]
pub(crate) struct SegmentOptionsArgs {
    /// A part and its seed: `NAME=tri:ID` (triangle id) or `NAME=point:X,Y,Z` (snapped to the
    /// nearest triangle). Repeat for each part; repeat a name for several seeds.
    #[arg(long = "part", value_name = "NAME=SEED")]
    pub(crate) parts: Vec<String>,
    /// Choose N parts automatically (farthest seeds on per-triangle motion statistics).
    #[arg(long, conflicts_with = "parts")]
    pub(crate) auto_parts: Option<usize>,
    /// Weight γ of the seam term (StopShop Eq. 1), after scaling the model to a unit box;
    /// ~1000 makes the cut independent of the exact seed placement (Fig. 4), much more
    /// collapses it.
    #[arg(long, default_value_t = DEFAULT_GAMMA)]
    pub(crate) gamma: f64,
    /// Laplacian smoothing iterations of the part boundaries (0: cut along mesh edges).
    #[arg(long = "smooth-iters")]
    pub(crate) smooth_iters: Option<usize>,
    /// Keep the seams as they move (skip Section 3.2).
    #[arg(long)]
    pub(crate) no_homogenize: bool,
    /// Reuse the cut and seam targets of an earlier segmentation of the same mesh (its
    /// `segmentation.json`, or the `.glb` next to it): parts of both clips assemble together.
    #[arg(long, value_name = "SEG.json|SEG.glb", conflicts_with_all = ["parts", "auto_parts"])]
    pub(crate) segmentation: Option<PathBuf>,
}

impl SegmentOptionsArgs {
    /// The job options (`figure`: also draw StopShop Fig. 5).
    ///
    /// # Errors
    /// A bad `--part` or an unreadable `--segmentation` file.
    pub(crate) fn options(&self, figure: bool) -> Result<SegmentJobOptions> {
        let mut segment = SegmentOptions {
            gamma: self.gamma,
            homogenize: !self.no_homogenize,
            ..SegmentOptions::default()
        };
        if let Some(k) = self.smooth_iters {
            segment.smooth_iterations = k;
        }
        let reuse = match &self.segmentation {
            Some(path) => Some(read_saved(path)?),
            None => None,
        };
        Ok(SegmentJobOptions {
            parts: parse_parts(&self.parts)?,
            auto_parts: self.auto_parts,
            figure,
            reuse,
            segment,
        })
    }
}

/// Reads `--segmentation`: a `segmentation.json` (a `.glb` stands for the `.json` of the same
/// name next to it, as `stopmo run` writes them).
fn read_saved(path: &Path) -> Result<::stopmo::segment::SavedSegmentation> {
    let json = if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"))
    {
        path.with_extension("json")
    } else {
        path.to_path_buf()
    };
    let bytes =
        tkio::read_file(&json).with_context(|| format!("--segmentation {}", path.display()))?;
    ::stopmo::saved_segmentation(&String::from_utf8_lossy(&bytes))
        .with_context(|| format!("--segmentation {}", json.display()))
}

/// Parses `NAME=tri:ID` or `NAME=point:X,Y,Z` and groups seeds by part name (in order).
fn parse_parts(specs: &[String]) -> Result<Vec<PartSpec>> {
    let mut parts: Vec<PartSpec> = Vec::new();
    for s in specs {
        let (name, seed) = s
            .split_once('=')
            .with_context(|| format!("--part {s}: expected NAME=tri:ID or NAME=point:X,Y,Z"))?;
        let seed = if let Some(id) = seed.strip_prefix("tri:") {
            Seed::Triangle(
                id.trim()
                    .parse()
                    .with_context(|| format!("--part {s}: bad triangle id"))?,
            )
        } else if let Some(p) = seed.strip_prefix("point:") {
            let v: Vec<f32> = p
                .split(',')
                .map(|x| x.trim().parse::<f32>())
                .collect::<Result<_, _>>()
                .with_context(|| format!("--part {s}: bad point"))?;
            if v.len() != 3 || !v.iter().all(|x| x.is_finite()) {
                bail!("--part {s}: a point needs three finite coordinates");
            }
            Seed::Point(Vec3::new(v[0], v[1], v[2]))
        } else {
            bail!("--part {s}: the seed must start with tri: or point:");
        };
        match parts.iter_mut().find(|p| p.name == name) {
            Some(p) => p.seeds.push(seed),
            None => parts.push(PartSpec::new(name, vec![seed])),
        }
    }
    Ok(parts)
}

/// Which algorithm picks the pieces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub(crate) enum MethodArg {
    /// Positions and velocities (StopShop Eq. 10, λ from --lambda).
    #[default]
    Stopshop,
    /// λ = 0: k-means on positions only.
    Kmeans,
    /// Uniform temporal sampling (the naive baseline).
    Uniform,
}

impl From<MethodArg> for Method {
    fn from(m: MethodArg) -> Method {
        match m {
            MethodArg::Stopshop => Method::StopShop,
            MethodArg::Kmeans => Method::KMeans,
            MethodArg::Uniform => Method::Uniform,
        }
    }
}

/// Library options shared by `stopmo library` and `stopmo run`.
#[derive(Debug, Args)]
pub(crate) struct LibraryOptionsArgs {
    /// Pieces per part: `20` for every part, or `upper=20,lower=30`.
    #[arg(long, value_name = "N|PART=N,...", conflicts_with_all = ["max_error", "budget"])]
    pub(crate) pieces: Option<String>,
    /// Smallest library per part whose worst frame's mean position error is at most this many
    /// millimetres (at --print-height).
    #[arg(long, value_name = "MM", conflicts_with = "budget")]
    pub(crate) max_error: Option<f64>,
    /// Total number of pieces over all parts, allocated greedily.
    #[arg(long, value_name = "PIECES")]
    pub(crate) budget: Option<usize>,
    /// Velocity weight λ of StopShop Eq. 10.
    #[arg(long, default_value_t = DEFAULT_LAMBDA)]
    pub(crate) lambda: f64,
    /// Random restarts (run in parallel, the best is kept).
    #[arg(long, default_value_t = DEFAULT_RESTARTS)]
    pub(crate) restarts: usize,
    /// Seed of every random choice (default: the tool's fixed seed; runs are reproducible).
    #[arg(long, value_name = "SEED")]
    pub(crate) seed: Option<u64>,
    /// Per-vertex saliency weights: float32 `.npy` of shape (vertices,) or (1, vertices), in
    /// the merged vertex order of the input (parts one after the other; for `stopmo run`, the
    /// input mesh's own vertex order, checked before anything is written).
    #[arg(long, value_name = "FILE.npy")]
    pub(crate) saliency: Option<PathBuf>,
    /// Frames that start a new, unrelated shot (no velocity term across them).
    #[arg(long, value_delimiter = ',')]
    pub(crate) cuts: Vec<usize>,
    /// Directory of pre-made pieces `<part>_<NN>.obj` (e.g. `OLD/pieces` of an earlier run);
    /// they are kept and new pieces are added up to the library size. The printed back
    /// surfaces `<part>_back.obj` there are reused, so the new pieces seat on the same head.
    #[arg(long, value_name = "DIR")]
    pub(crate) fixed: Option<PathBuf>,
    /// Algorithm.
    #[arg(long, value_enum, default_value_t = MethodArg::Stopshop)]
    pub(crate) method: MethodArg,
    /// Printed height of the whole model in millimetres (scales the STL files and the errors).
    #[arg(long, value_name = "MM", default_value_t = DEFAULT_PRINT_HEIGHT_MM)]
    pub(crate) print_height: f64,
    /// Wall thickness of the printed pieces in millimetres.
    #[arg(long, value_name = "MM", default_value_t = DEFAULT_THICKNESS_MM)]
    pub(crate) thickness: f64,
    /// Add male/female plugs (paper Fig. 13) across every seam shared by two parts: a pin
    /// under the first part, a socket tube under the second, fused into the pieces' STL files
    /// as extra shells (slicers union them). Placed on the rest geometry; listed in
    /// report.json under "plugs".
    #[arg(long)]
    pub(crate) plugs: bool,
    /// Pin radius of the plugs in millimetres.
    #[arg(long, value_name = "MM", requires = "plugs", default_value_t = DEFAULT_PLUG_RADIUS_MM)]
    pub(crate) plug_radius: f64,
    /// Plug length (boss + pin) in millimetres.
    #[arg(long, value_name = "MM", requires = "plugs", default_value_t = DEFAULT_PLUG_LENGTH_MM)]
    pub(crate) plug_length: f64,
    /// Radial clearance between pin and socket in millimetres (tune to the printer;
    /// default: --clearance when given, else 0.15).
    #[arg(long, value_name = "MM", requires = "plugs")]
    pub(crate) plug_clearance: Option<f64>,
    /// A disc magnet DIAMETERxHEIGHT in millimetres (e.g. 3x2): every piece gets a pocket
    /// for it at one place of its part's back that all pieces share (so one magnet in the
    /// head holds every piece), and the part's mount pieces/<part>_back.stl the matching
    /// pocket.
    #[arg(long, value_name = "DxH", conflicts_with = "no_print")]
    pub(crate) magnets: Option<String>,
    /// Clearance of printed fits in millimetres (magnet pockets, the mount's key sockets and
    /// plugs); default: 3 × --resolution, at least 0.1 (0.15 at 0.05 mm: a tight resin fit;
    /// 0.3 gives a loose one).
    #[arg(long, value_name = "MM", allow_negative_numbers = true)]
    pub(crate) clearance: Option<f64>,
    /// Files of the printable solids: one STL per piece, one library.3mf (every piece a
    /// named object, one colour per part, laid out on build plates), or both.
    #[arg(long, value_name = "stl|3mf|stl,3mf", default_value = "stl")]
    pub(crate) print_format: String,
    /// Build plate WIDTHxDEPTH in millimetres where library.3mf lays the pieces out.
    #[arg(long, value_name = "WxD", default_value_t = plate_spec(::stopmo::DEFAULT_PLATE_MM))]
    pub(crate) plate: String,
    /// The printer's thinnest wall in millimetres: thinner walls of a piece or mount are
    /// reported (a warning naming the pieces and the fix, report.json
    /// "printing.printability"); magnet pockets keep at least this much material around.
    #[arg(
        long,
        value_name = "MM",
        default_value_t = ::stopmo::DEFAULT_MIN_WALL_MM,
        allow_negative_numbers = true
    )]
    pub(crate) min_wall: f64,
    /// The printer's smallest free-standing feature in millimetres: smaller embossed IDs,
    /// keys or plug pins are reported.
    #[arg(
        long,
        value_name = "MM",
        default_value_t = ::stopmo::DEFAULT_MIN_FEATURE_MM,
        allow_negative_numbers = true
    )]
    pub(crate) min_feature: f64,
    /// Printer resolution in millimetres: pieces that differ from a sibling by less are
    /// reported (a warning and report.json "printing.parts[].below_resolution").
    #[arg(long, value_name = "MM", default_value_t = ::stopmo::DEFAULT_RESOLUTION_MM)]
    pub(crate) resolution: f64,
    /// No registration keys (domes on the shared back surface that fix all six degrees of
    /// freedom on the armature/head).
    #[arg(long)]
    pub(crate) no_keys: bool,
    /// No piece ID (`P-NN`) embossed on the back of every piece.
    #[arg(long)]
    pub(crate) no_ids: bool,
    /// No printable solids: the pieces' surfaces (`pieces/*.obj`), labels, errors and
    /// sheets only, in a fraction of the time — to judge a library size before printing it.
    #[arg(long, conflicts_with = "plugs")]
    pub(crate) no_print: bool,
    /// Also write the JSON report here (it is always written to DIR/report.json).
    #[arg(long)]
    pub(crate) report: Option<PathBuf>,
}

impl LibraryOptionsArgs {
    /// The job options for parts named `names`, reading the saliency and fixed-piece files.
    ///
    /// # Errors
    /// A bad `--pieces`, `--max-error` or `--thickness`, or an unreadable `--saliency` file
    /// or `--fixed` folder.
    pub(crate) fn options(&self, names: &[String]) -> Result<LibraryJobOptions> {
        let pieces = match (&self.pieces, self.max_error, self.budget) {
            (Some(p), _, _) => parse_pieces(p)?,
            (None, Some(e), _) => PieceCount::MaxErrorMm(e),
            (None, None, Some(b)) => PieceCount::Budget(b),
            (None, None, None) => PieceCount::default(),
        };
        if let Some(c) = self.clearance {
            let r = ::stopmo::CLEARANCE_RANGE_MM;
            if !(c.is_finite() && r.contains(&c)) {
                bail!(
                    "--clearance must be between {} and {} millimetres, got {c}",
                    r.start(),
                    r.end()
                );
            }
        }
        let magnets = match &self.magnets {
            Some(m) => Some(
                ::stopmo::library::MagnetOptions::parse(m)
                    .with_context(|| format!("--magnets {m}"))?,
            ),
            None => None,
        };
        let Some(print_format) = ::stopmo::PrintFormat::parse(&self.print_format) else {
            bail!(
                "--print-format {}: expected stl, 3mf or stl,3mf",
                self.print_format
            );
        };
        let plate_mm = parse_plate(&self.plate)?;
        for (flag, v) in [
            ("--min-wall", self.min_wall),
            ("--min-feature", self.min_feature),
        ] {
            let r = ::stopmo::PRINTER_MINIMUM_RANGE_MM;
            if !(v.is_finite() && r.contains(&v)) {
                bail!(
                    "{flag} must be between {} and {} millimetres, got {v}",
                    r.start(),
                    r.end()
                );
            }
        }
        let saliency = match &self.saliency {
            Some(p) => Some(tkio::npy::read_per_vertex(p)?),
            None => None,
        };
        let (fixed, backs) = match &self.fixed {
            Some(dir) => {
                let files =
                    tkio::obj::read_folder(dir, |stem| ::stopmo::is_library_piece(stem, names))
                        .with_context(|| format!("--fixed {}", dir.display()))?;
                ::stopmo::library_pieces(names, files)
            }
            None => (BTreeMap::new(), BTreeMap::new()),
        };
        let options = LibraryJobOptions {
            pieces,
            method: self.method.into(),
            solve: SolveOptions {
                lambda: self.lambda,
                restarts: self.restarts,
                seed: self.seed.unwrap_or(DEFAULT_SEED),
                ..SolveOptions::default()
            },
            print_height_mm: self.print_height,
            thickness_mm: self.thickness,
            plugs: self.plugs.then(|| PlugOptions {
                radius_mm: self.plug_radius,
                length_mm: self.plug_length,
                clearance_mm: self
                    .plug_clearance
                    .or(self.clearance)
                    .unwrap_or(DEFAULT_PLUG_CLEARANCE_MM),
                ..PlugOptions::default()
            }),
            saliency,
            cuts: self.cuts.clone(),
            fixed,
            backs,
            resolution_mm: self.resolution,
            keys: !self.no_keys,
            ids: !self.no_ids,
            magnets,
            clearance_mm: self.clearance,
            print_format,
            plate_mm,
            min_wall_mm: self.min_wall,
            min_feature_mm: self.min_feature,
            print: !self.no_print,
        };
        // The core's checks of the lengths, before the job reads its input.
        options.check_lengths().map_err(|e| {
            let flag = match e.option() {
                Some("max_error_mm") => format!("--max-error {}", self.max_error.unwrap_or(0.0)),
                _ => format!("--thickness {}", self.thickness),
            };
            FlagError::At {
                at: flag,
                source: Box::new(e),
            }
        })?;
        Ok(options)
    }

    /// Names the file or option a library error is about: `--saliency FILE`, `--fixed DIR`,
    /// `--pieces …`, otherwise the input.
    pub(crate) fn context(&self, e: ::stopmo::Error, input: &Path) -> FlagError {
        let at = match (e.option(), &self.saliency, &self.fixed) {
            (Some("saliency"), Some(p), _) => p.display().to_string(),
            (Some("fixed"), _, Some(d)) => format!("--fixed {}", d.display()),
            (Some("resolution_mm"), _, _) => format!("--resolution {}", self.resolution),
            (Some("magnets"), _, _) => {
                format!("--magnets {}", self.magnets.as_deref().unwrap_or(""))
            }
            (Some("pieces"), _, _) => format!("--pieces {}", self.pieces.as_deref().unwrap_or("")),
            _ => input.display().to_string(),
        };
        FlagError::At {
            at,
            source: Box::new(e),
        }
    }
}

/// A plate as `--plate` writes it: `WxD` in millimetres.
fn plate_spec([w, d]: [f64; 2]) -> String {
    format!("{w}x{d}")
}

/// Parses `--plate`: `WxD` in millimetres, each in [`::stopmo::PLATE_SIDE_RANGE_MM`].
fn parse_plate(spec: &str) -> Result<[f64; 2]> {
    let r = ::stopmo::PLATE_SIDE_RANGE_MM;
    let parsed = spec
        .trim()
        .split_once(['x', 'X'])
        .and_then(|(w, d)| Some([w.trim().parse::<f64>().ok()?, d.trim().parse::<f64>().ok()?]));
    match parsed {
        Some(p) if p.iter().all(|v| v.is_finite() && r.contains(v)) => Ok(p),
        _ => bail!(
            "--plate {spec}: expected WIDTHxDEPTH in millimetres ({} to {} each), e.g. {}",
            r.start(),
            r.end(),
            plate_spec(::stopmo::DEFAULT_PLATE_MM)
        ),
    }
}

/// Parses `--pieces`: `N` or `PART=N,...`.
fn parse_pieces(spec: &str) -> Result<PieceCount> {
    let spec = spec.trim();
    if let Ok(n) = spec.parse::<usize>() {
        return Ok(PieceCount::Each(n));
    }
    let mut sizes = BTreeMap::new();
    for item in spec.split(',') {
        let (name, n) = item
            .split_once('=')
            .with_context(|| format!("--pieces {spec}: expected N or PART=N,..."))?;
        let n: usize = n
            .trim()
            .parse()
            .with_context(|| format!("--pieces {spec}: bad count '{n}'"))?;
        sizes.insert(name.trim().to_string(), n);
    }
    Ok(PieceCount::PerPart(sizes))
}
