//! The inputs of the accuracy report that an all-modes solve computes on idle core time
//! ([`crate::runtime::idle_task`]) instead of on its critical path.

use crate::certify::idle_certificate::BottomCertificate;
use crate::certify::sketch::SketchRows;
use crate::linalg::norms::frobenius_norm;
use crate::problem::PencilProblem;
use crate::runtime::idle_task::IdleTask;

/// What an all-modes solve computes on idle core time from its start ([`IdleTask`]): the
/// Frobenius norms of A and B and, for a sketched report, the sketch's rows S·A and S·B.
pub(crate) struct EarlyInputs {
    pub(crate) norms: (f64, f64),
    pub(crate) sketch_rows: Option<SketchRows>,
}

impl EarlyInputs {
    /// Starts the task (None when no thread could be started).
    pub(crate) fn start(problem: &PencilProblem, sketched: bool) -> Option<IdleTask<Self>> {
        let problem = problem.clone();
        IdleTask::spawn("mechanica-idle-inputs", move |stop| {
            let (a, b) = (problem.a(), problem.b());
            let norms = (frobenius_norm(a), frobenius_norm(b));
            if stop.load(std::sync::atomic::Ordering::Acquire) {
                return None;
            }
            let sketch_rows = sketched.then(|| SketchRows::new(a, b));
            Some(Self { norms, sketch_rows })
        })
    }
}

/// What idle core time delivered to the report (each None when not started or not finished).
#[derive(Default)]
pub(crate) struct IdleResults {
    /// The bottom certificate's shift and its factorization begun on idle time, module
    /// [`crate::certify::idle_certificate`].
    pub(crate) certificate: Option<BottomCertificate>,
    /// The sketch's S·A and S·B.
    pub(crate) sketch_rows: Option<SketchRows>,
}
