//! `rinscope selfcal`: the IMU's self-calibration on its own gimbals, simulated or from a log set
//! (the command's owner is `app::selfcal::execute`, the estimator `calib::selfcal`).

use super::commands::print_saved;
use super::{Failure, SelfcalArgs};
use crate::app::selfcal::{SelfcalInput, SelfcalRequest, SequenceChoice, execute};
use crate::app::terminate::stop_flag;

/// `rinscope selfcal`.
pub(super) fn selfcal(args: &SelfcalArgs) -> Result<(), Failure> {
    let input = match &args.log {
        Some(dir) => SelfcalInput::Log(Box::new(crate::scenario::logset::load(dir)?)),
        None if !args.merge.is_empty() => SelfcalInput::Merge(args.merge.clone()),
        None if args.shard.is_some() => {
            let shard = crate::calib::montecarlo::Shard::parse(args.shard.as_deref().unwrap_or_default())
                .map_err(|e| Failure::input(format!("--shard {e}")))?;
            SelfcalInput::Shard {
                params: Box::new(args.source.load("selfcal-nav-grade")?),
                sequence: SequenceChoice::parse(&args.sequence)
                    .map_err(|e| Failure::input(format!("--sequence {e}")))?,
                encoders: !args.without_encoders,
                runs: args.monte_carlo.unwrap_or(2) as usize,
                shard,
            }
        }
        None => {
            let params = args.source.load("selfcal-nav-grade")?;
            let sequence =
                SequenceChoice::parse(&args.sequence).map_err(|e| Failure::input(format!("--sequence {e}")))?;
            SelfcalInput::Scenario {
                params: Box::new(params),
                sequence,
                monte_carlo: args.monte_carlo.map(|n| n as usize),
                navigate_hours: args.navigate_hours,
                plan_only: args.plan,
                encoders: !args.without_encoders,
            }
        }
    };
    let recording = if args.no_recording || args.plan || args.shard.is_some() || !args.merge.is_empty() {
        None
    } else {
        Some(args.sinks.recording()?)
    };
    let report = execute(&SelfcalRequest { input, recording, json: args.json.clone() }, &stop_flag())?;
    out!("{}", report.text);
    if let Some(saved) = &report.saved {
        print_saved(saved);
    }
    Ok(())
}
