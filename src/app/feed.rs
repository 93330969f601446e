//! The one way a producer (a run's simulation, a replay's loop) hands its outputs to a recorder:
//! rows buffered into batches and sent through a bounded channel to the recorder's own thread,
//! which turns them into Rerun chunks. The producer never waits for the encoding (only for a full
//! channel: memory stays flat); a recorder that failed closes the channel and the producer stops.

use crate::ins::core::SampleOut;
use crate::ins::pipeline::InsView;
use crate::record::{RecordError, Recorder, Solution};
use crate::sim::StepOutput;

/// Rows per message to the recorder.
const BATCH_ROWS: usize = 2048;

/// One output instant: the turntable-only demodulations and, with an IMU in the loop, the INS's
/// view; a replay's also the INS's own solution.
#[derive(Debug, Clone)]
pub struct OutputRow {
    /// Ideal-INS step (truth, encoders, the three demodulations).
    pub core: StepOutput,
    /// The INS in the loop, if any.
    pub ins: Option<InsView>,
    /// A replay's: the INS's own solution.
    pub solution: Option<Solution>,
}

/// What a producer sends.
pub(crate) enum Batch {
    Series(Vec<OutputRow>),
    Scene(Vec<OutputRow>),
    Signal(Vec<SampleOut>),
}

/// Batches of updates the channel from a producer (a run's simulation, a replay's loop) to its
/// statistics' thread holds. Four to six threads share two cores: the scheduler leaves a runnable
/// thread waiting for up to its period (~12-24 ms here), and a producer whose channel holds less
/// than that stops when its consumer is descheduled, with a core idle.
/// Four batches of 512 updates were ~6 ms of a 2 kHz run: in a `run` of pyins' coning stream the
/// simulation (0.33-0.36 s of CPU) waited 0.12-0.15 s on a full channel; its static stream's `run`
/// kept 1.1 of the 2 cores busy. 64 hold ~100 ms, and it waits 0.00-0.02 s (a bound in updates,
/// not in time: memory stays flat, ≤ 12 MB at five algorithms). The producer may then be that far
/// ahead of what is recorded: the statistics' thread answers a signal itself, at its next batch.
pub(crate) const STAGE_BATCHES: usize = 64;

/// The channel a producer sends its batches through.
pub(crate) fn channel() -> (crossbeam_channel::Sender<Batch>, crossbeam_channel::Receiver<Batch>) {
    crossbeam_channel::bounded(8)
}

/// Buffers rows and sends them in batches; each call is `false` when the recorder has gone away.
pub(crate) struct Outbox<'a> {
    tx: &'a crossbeam_channel::Sender<Batch>,
    series: Vec<OutputRow>,
    scene: Vec<OutputRow>,
    signal: Vec<SampleOut>,
}

impl<'a> Outbox<'a> {
    pub(crate) fn new(tx: &'a crossbeam_channel::Sender<Batch>) -> Self {
        Self { tx, series: Vec::new(), scene: Vec::new(), signal: Vec::new() }
    }
    /// A row of the plots.
    pub(crate) fn series(&mut self, r: OutputRow) -> bool {
        self.series.push(r);
        self.series.len() < BATCH_ROWS || self.tx.send(Batch::Series(fresh(&mut self.series))).is_ok()
    }
    /// A frame of the 3D scene.
    pub(crate) fn scene(&mut self, r: OutputRow) -> bool {
        self.scene.push(r);
        self.scene.len() < BATCH_ROWS || self.tx.send(Batch::Scene(fresh(&mut self.scene))).is_ok()
    }
    /// A sample of the gyro signal window.
    pub(crate) fn signal(&mut self, s: SampleOut) -> bool {
        self.signal.push(s);
        self.signal.len() < BATCH_ROWS || self.tx.send(Batch::Signal(fresh(&mut self.signal))).is_ok()
    }
    /// Sends what is left.
    pub(crate) fn close(self) {
        // A closed receiver means the recorder failed; it reports the error itself.
        let _ = self.tx.send(Batch::Signal(self.signal));
        let _ = self.tx.send(Batch::Series(self.series));
        let _ = self.tx.send(Batch::Scene(self.scene));
    }
}

/// The full batch out of `buffer`, which starts the next one at its full size (growing a batch
/// row by row from empty copied every row about twice: a tenth of the simulation thread's time).
fn fresh<T>(buffer: &mut Vec<T>) -> Vec<T> {
    std::mem::replace(buffer, Vec::with_capacity(BATCH_ROWS))
}

/// The recorder's side: every batch from `rx` into `recorder` until the producer closes the
/// channel; on the first error it stops (dropping `rx`: the producer's next send fails).
pub(crate) fn consume(recorder: &mut Recorder, rx: crossbeam_channel::Receiver<Batch>) -> Result<(), RecordError> {
    for batch in &rx {
        match batch {
            Batch::Series(rows) => rows.iter().try_for_each(|o| match (&o.ins, &o.solution) {
                (Some(ins), Some(solution)) => recorder.push_replay_row(&o.core, ins, solution),
                _ => recorder.push_row(&o.core, o.ins.as_ref()),
            })?,
            Batch::Scene(rows) => rows.iter().try_for_each(|o| recorder.push_scene_row(&o.core, o.ins.as_ref()))?,
            Batch::Signal(samples) => samples.iter().try_for_each(|o| recorder.push_signal(o))?,
        }
    }
    Ok(())
}
