//! `blutrace.Characterisation`: a part of a scene characterised into an IS BSDF table, what
//! `Scene.characterise` returns (the library's `blutrace::characterise`, as `blutrace
//! bsdf` runs it): the part found, the fates per incidence as numpy arrays, and the table
//! as text or written to a file.

use crate::convert::{arg, count, run_error};
use crate::detached::run_detached;
use crate::progress;
use blutrace::characterise::{Characterised, Fates, Options, characterise_until};
use blutrace::optics::bsdf_table::format;
use blutrace::run::Interrupt;
use blutrace::scene::Scene as RustScene;
use numpy::IntoPyArray;
use numpy::ndarray::Array2;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};

/// A characterised part (``Scene.characterise``): ``part`` says what was found (the face
/// alone, or the slab behind it), ``fates`` the fractions of the photons reflected,
/// transmitted, absorbed and lost at each incidence, ``to_bsdf()`` the IS BSDF table, and
/// ``write(path)`` writes it for a ``bsdf_table`` face.
/// It pickles (its values and the table's text), so an executor can return it.
#[pyclass(module = "blutrace", name = "Characterisation", frozen)]
pub struct Characterisation {
    /// What the part was found to be.
    part: String,
    /// Per (rotation, AOI), rotation-major: reflected, transmitted, absorbed, lost.
    fates: Vec<[f64; 4]>,
    aoi: Vec<f64>,
    rotations: Vec<f64>,
    /// The IS BSDF table's text.
    bsdf: String,
    /// The files the scene read, which `write` must not replace.
    reads: Vec<PathBuf>,
}

impl Characterisation {
    /// The characterisation of `inner`, its table commented with `comments`.
    fn new(
        inner: &Characterised,
        aoi: Vec<f64>,
        rotations: Vec<f64>,
        comments: &[String],
        reads: Vec<PathBuf>,
    ) -> Characterisation {
        let fates = inner
            .fates
            .iter()
            .map(|f: &Fates| [f.reflected, f.transmitted, f.absorbed, f.lost])
            .collect();
        Characterisation {
            part: inner.part.clone(),
            fates,
            aoi,
            rotations,
            bsdf: format::write(&inner.sections, comments),
            reads,
        }
    }
}

#[pymethods]
impl Characterisation {
    /// What the part was found to be.
    #[getter]
    fn part(&self) -> String {
        self.part.clone()
    }

    /// The angles of incidence (degrees).
    #[getter]
    fn aoi(&self) -> Vec<f64> {
        self.aoi.clone()
    }

    /// The sample rotations (degrees).
    #[getter]
    fn rotations(&self) -> Vec<f64> {
        self.rotations.clone()
    }

    /// ``{"reflected", "transmitted", "absorbed", "lost"}``: fractions of the photons, each
    /// a ``(len(rotations), len(aoi))`` float64 array.
    #[getter]
    fn fates<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let shape = (self.rotations.len(), self.aoi.len());
        let d = PyDict::new(py);
        let names = ["reflected", "transmitted", "absorbed", "lost"];
        for (k, name) in names.into_iter().enumerate() {
            let values = self.fates.iter().map(|f| f[k]).collect();
            let a = Array2::from_shape_vec(shape, values).expect("a fate per incidence");
            d.set_item(name, a.into_pyarray(py))?;
        }
        Ok(d)
    }

    /// The IS BSDF table (the text of a ``.bsdf`` file).
    fn to_bsdf(&self) -> String {
        self.bsdf.clone()
    }

    /// Write the table to ``path`` (a ``.bsdf`` file), whole or not at all.
    fn write(
        &self,
        py: Python<'_>,
        #[pyo3(from_py_with = crate::convert::path_arg)] path: PathBuf,
    ) -> PyResult<()> {
        let text = &self.bsdf;
        py.detach(|| blutrace::output::atomic::write_file(&path, text.as_bytes(), &self.reads))
            .map_err(run_error)
    }

    /// It pickles as its values: `Characterisation._restore(state)`.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let restore = py.get_type::<Characterisation>().getattr("_restore")?;
        let state = (
            self.part.clone(),
            self.fates.clone(),
            self.aoi.clone(),
            self.rotations.clone(),
            self.bsdf.clone(),
            self.reads.clone(),
        );
        let args = (state,).into_pyobject(py)?.into_any();
        PyTuple::new(py, [restore, args])
    }

    /// The inverse of pickling.
    #[staticmethod]
    fn _restore(state: State) -> Characterisation {
        let (part, fates, aoi, rotations, bsdf, reads) = state;
        Characterisation {
            part,
            fates,
            aoi,
            rotations,
            bsdf,
            reads,
        }
    }

    fn __repr__(&self) -> String {
        format!(
            "Characterisation(part={:?}, aoi={:?}, rotations={:?})",
            self.part, self.aoi, self.rotations
        )
    }
}

/// What a characterisation pickles as: part, fates, aoi, rotations, table, reads.
type State = (
    String,
    Vec<[f64; 4]>,
    Vec<f64>,
    Vec<f64>,
    String,
    Vec<PathBuf>,
);

/// `Scene.characterise`'s arguments (the CLI's defaults).
pub struct Args<'a, 'py> {
    pub tag: &'a str,
    pub photons: Option<&'a Bound<'py, PyAny>>,
    pub aoi: Vec<f64>,
    pub rotations: Vec<f64>,
    pub radial_step: f64,
    pub azimuth_step: f64,
    pub u_axis: Option<[f64; 3]>,
    pub seed: Option<&'a Bound<'py, PyAny>>,
    pub progress: Option<&'a Bound<'py, PyAny>>,
}

/// Characterise the part of `scene` that `args` name, off the GIL, reporting photons done
/// (whole incidences) to `args.progress`; Ctrl-C stops it before the next incidence and
/// raises.
pub fn characterise_scene(
    py: Python<'_>,
    scene: &RustScene,
    args: Args<'_, '_>,
) -> PyResult<Characterisation> {
    crate::options::tag_arg(scene, args.tag)?;
    let photons = args
        .photons
        .map_or(Ok(1_000_000), |p| count(p, "photons", 1))?;
    let seed = args.seed.map_or(Ok(1), |s| count(s, "seed", 0))?;
    let opts = Options {
        tag: args.tag.to_string(),
        photons,
        aoi_deg: args.aoi,
        rotations_deg: args.rotations,
        radial_step_deg: args.radial_step,
        azimuth_step_deg: args.azimuth_step,
        u_axis: args.u_axis,
        seed,
    };
    let total = photons.saturating_mul((opts.aoi_deg.len() * opts.rotations_deg.len()) as u64);
    let reporter = progress::reporter(py, args.progress, total)?;
    let done = AtomicU64::new(0);
    let interrupt = Interrupt::default();
    let stop = |k: usize| {
        done.store(k as u64 * photons, Ordering::Relaxed);
        interrupt.requested()
    };
    let work = || characterise_until(scene, &opts, &stop);
    let tick = |py: Python<'_>| progress::update(py, &reporter, done.load(Ordering::Relaxed));
    let made = run_detached(py, &interrupt, work, tick);
    // An interrupt or an error of the work outranks one of the progress display.
    let finished = matches!(made, Ok(Ok(_)));
    let last = if finished {
        total
    } else {
        done.load(Ordering::Relaxed)
    };
    let closed = progress::close(py, &reporter, last);
    let inner =
        made?.map_err(|e| PyValueError::new_err(format!("{}: {e:#}", scene.path.display())))?;
    closed?;
    let comments = vec![
        format!(
            "blutrace Scene.characterise of {} at tag {}",
            scene.path.display(),
            opts.tag
        ),
        format!("part: {}", inner.part),
        format!("{photons} photons per incidence, seed {seed}"),
    ];
    Ok(Characterisation::new(
        &inner,
        opts.aoi_deg,
        opts.rotations_deg,
        &comments,
        scene.inputs.clone(),
    ))
}

/// Argument `radial_step` (degrees).
pub fn radial_step(v: &Bound<'_, PyAny>) -> PyResult<f64> {
    arg(v, "radial_step")
}

/// Argument `azimuth_step` (degrees).
pub fn azimuth_step(v: &Bound<'_, PyAny>) -> PyResult<f64> {
    arg(v, "azimuth_step")
}
