//! The viewer layout sent with every recording: a small declarative blueprint that, unlike the SDK's
//! `rerun::blueprint` builders (0.36), can also set view properties — the 3D eye and the plots' time
//! range — so the recording opens ready to read.

use rerun::blueprint::components::{ContainerKind, PanelState, PlayState, RootContainer};
use rerun::external::re_log_types::{BlueprintActivationCommand, LogMsg};
use rerun::external::re_sdk_types::blueprint::archetypes as bp;
use rerun::external::re_sdk_types::blueprint::components as bpc;
use rerun::external::re_sdk_types::datatypes;
use rerun::{AsComponents, RecordingStream, RecordingStreamBuilder, RecordingStreamResult};

/// A view or a container of the layout.
#[derive(Clone)]
pub enum Node {
    /// A container of children.
    Container {
        /// Tabs, horizontal, vertical or grid.
        kind: ContainerKind,
        /// Children in order.
        children: Vec<Node>,
        /// Relative sizes along the container's axis (empty: equal).
        shares: Vec<f32>,
        /// Its title (a tab's), if any.
        name: Option<String>,
    },
    /// A view.
    View {
        /// "3D", "TimeSeries", "TextDocument", "TextLog".
        class: &'static str,
        /// Title.
        name: String,
        /// Space origin (entity path).
        origin: String,
        /// (property archetype name, its components).
        properties: Vec<(&'static str, Vec<rerun::SerializedComponentBatch>)>,
    },
}

impl Node {
    /// A container.
    #[must_use]
    pub fn container(kind: ContainerKind, children: Vec<Node>, shares: &[f32]) -> Self {
        Self::Container { kind, children, shares: shares.to_vec(), name: None }
    }

    /// A container with a title (what its tab shows inside a tab container).
    #[must_use]
    pub fn named_container(kind: ContainerKind, name: &str, children: Vec<Node>, shares: &[f32]) -> Self {
        Self::Container { kind, children, shares: shares.to_vec(), name: Some(name.to_owned()) }
    }

    /// A view with no properties.
    #[must_use]
    pub fn view(class: &'static str, name: impl Into<String>, origin: impl Into<String>) -> Self {
        Self::View { class, name: name.into(), origin: origin.into(), properties: Vec::new() }
    }

    /// Gives every time-series view under this node that has no value range the range `range`
    /// returns for its space origin (None: left to the viewer).
    pub fn fit_plots_without_range(&mut self, range: &dyn Fn(&str) -> Option<(f64, f64)>) {
        match self {
            Self::Container { children, .. } => {
                for c in children {
                    c.fit_plots_without_range(range);
                }
            }
            Self::View { class, origin, properties, .. } => {
                if *class == "TimeSeries"
                    && !properties.iter().any(|(n, _)| *n == "ScalarAxis")
                    && let Some((lo, hi)) = range(origin)
                {
                    properties.push(("ScalarAxis", scalar_range(lo, hi).as_serialized_batches()));
                }
            }
        }
    }

    /// Adds a view property (e.g. `EyeControls3D`, `TimeAxis`).
    #[must_use]
    pub fn with_property(mut self, name: &'static str, archetype: &dyn AsComponents) -> Self {
        if let Self::View { properties, .. } = &mut self {
            properties.push((name, archetype.as_serialized_batches()));
        }
        self
    }
}

/// A plot that always shows the whole run, not a window around the time cursor.
#[must_use]
pub fn whole_run_time_axis() -> bp::TimeAxis {
    bp::TimeAxis::new().with_view_range(bpc::TimeRange(datatypes::TimeRange::EVERYTHING))
}

/// A plot of the first `seconds` of the run only (signals recorded over a short window).
#[must_use]
pub fn window_time_axis(seconds: f64) -> bp::TimeAxis {
    let end = datatypes::TimeInt((seconds * 1e9) as i64);
    bp::TimeAxis::new().with_view_range(bpc::TimeRange(datatypes::TimeRange {
        start: datatypes::TimeRangeBoundary::Absolute(datatypes::TimeInt(0)),
        end: datatypes::TimeRangeBoundary::Absolute(end),
    }))
}

/// A plot of the timeline's range `[lo_s, hi_s]` (s, or whatever the timeline's seconds stand for).
#[must_use]
pub fn time_axis_range(lo_s: f64, hi_s: f64) -> bp::TimeAxis {
    let at = |s: f64| datatypes::TimeRangeBoundary::Absolute(datatypes::TimeInt((s * 1e9) as i64));
    bp::TimeAxis::new().with_view_range(bpc::TimeRange(datatypes::TimeRange { start: at(lo_s), end: at(hi_s) }))
}

/// A plot's value axis fixed to `[lo, hi]` (a filter's prior would otherwise set the scale).
#[must_use]
pub fn scalar_range(lo: f64, hi: f64) -> bp::ScalarAxis {
    bp::ScalarAxis::new().with_range(rerun::components::Range1D(datatypes::Range1D([lo, hi])))
}

/// A symmetric plot range for data within ±`h` (a [`crate::math::units::nice_half_range`]):
/// ±1.25 h. The plot labels its grid at powers of ten only, and drops the labels on the border,
/// so ±h itself (h = 10^k) would show "0" alone; at ±1.25 h the ticks at ±h are inside. Measured
/// in the viewer at 1600×1000 (plots ~170 px high): h = 1, 2, 3 × 10^k give 3, 5 and 7 labelled
/// ticks.
pub fn symmetric_range(h: f64) -> bp::ScalarAxis {
    scalar_range(-1.25 * h, 1.25 * h)
}

/// No legend (the view's title names the lines).
#[must_use]
pub fn no_legend() -> bp::PlotLegend {
    bp::PlotLegend::new().with_visible(false)
}

pub use bpc::Corner2D as LegendCorner;

/// The legend in a corner of the plot.
#[must_use]
pub fn legend_at(corner: LegendCorner) -> bp::PlotLegend {
    bp::PlotLegend::new().with_corner(corner)
}

/// A time-series view over the whole run with its legend in `legend` (None: hidden, the view's
/// title names the lines).
#[must_use]
pub fn whole_run_plot(name: &str, origin: &str, legend: Option<LegendCorner>) -> Node {
    Node::view("TimeSeries", name, origin)
        .with_property("TimeAxis", &whole_run_time_axis())
        .with_property("PlotLegend", &legend.map_or_else(no_legend, legend_at))
}

/// A 3D eye looking at `target` from `position` with +z up.
#[must_use]
pub fn eye(position: [f32; 3], target: [f32; 3]) -> bp::EyeControls3D {
    bp::EyeControls3D::new()
        .with_kind(bpc::Eye3DKind::Orbital)
        .with_position(position)
        .with_look_target(target)
        .with_eye_up([0.0, 0.0, 1.0])
}

/// Deterministic UUID-shaped ids: the same scenario gives the same blueprint.
struct Ids(u64);

impl Ids {
    fn next(&mut self) -> String {
        self.0 += 1;
        format!("00000000-0000-4000-8000-{:012x}", self.0)
    }

    /// The bytes of the id `next` last returned.
    fn last_bytes(&self) -> [u8; 16] {
        let mut b = [0u8; 16];
        b[6] = 0x40;
        b[8] = 0x80;
        b[10..].copy_from_slice(&self.0.to_be_bytes()[2..]);
        b
    }
}

fn log_node(node: &Node, stream: &RecordingStream, ids: &mut Ids) -> RecordingStreamResult<String> {
    match node {
        Node::View { class, name, origin, properties } => {
            let path = format!("view/{}", ids.next());
            stream.log(
                format!("{path}/ViewContents"),
                &bp::ViewContents::new([bpc::QueryExpression("$origin/**".into())]),
            )?;
            stream.log(
                path.as_str(),
                &bp::ViewBlueprint::new(bpc::ViewClass((*class).into()))
                    .with_display_name(name.as_str())
                    .with_space_origin(origin.as_str()),
            )?;
            for (prop, batches) in properties {
                stream.log_serialized_batches(format!("{path}/{prop}"), false, batches.iter().cloned())?;
            }
            Ok(path)
        }
        Node::Container { kind, children, shares, name } => {
            let mut child_paths = Vec::new();
            for c in children {
                child_paths.push(log_node(c, stream, ids)?);
            }
            let path = format!("container/{}", ids.next());
            let mut arch = bp::ContainerBlueprint::new(*kind)
                .with_contents(child_paths.iter().map(|p| bpc::IncludedContent(p.as_str().into())));
            if let Some(name) = name {
                arch = arch.with_display_name(name.as_str());
            }
            if !shares.is_empty() {
                let s = shares.iter().map(|&x| bpc::ColumnShare(datatypes::Float32(x)));
                let r = shares.iter().map(|&x| bpc::RowShare(datatypes::Float32(x)));
                arch = match kind {
                    ContainerKind::Horizontal => arch.with_col_shares(s),
                    _ => arch.with_row_shares(r),
                };
            }
            stream.log(path.as_str(), &arch)?;
            Ok(path)
        }
    }
}

/// Time-panel settings.
pub struct Playback {
    /// Timeline name.
    pub timeline: &'static str,
    /// Playback speed multiplier.
    pub speed: f64,
    /// Follow the newest data (live sessions) instead of playing from the start.
    pub follow: bool,
}

/// Sends `root` as the active and default layout of `rec`'s application.
pub fn send(
    rec: &RecordingStream,
    application_id: &'static str,
    root: &Node,
    playback: &Playback,
) -> RecordingStreamResult<()> {
    let (bp_stream, storage) = RecordingStreamBuilder::new(application_id).blueprint().memory()?;
    bp_stream.set_time_sequence("blueprint", 0);
    let mut ids = Ids(0);
    // The root is a container, logged last, so its id is the last one handed out.
    log_node(root, &bp_stream, &mut ids)?;
    let root_uuid = datatypes::Uuid { bytes: ids.last_bytes() };
    bp_stream.log(
        "viewport",
        &bp::ViewportBlueprint::new()
            .with_root_container(RootContainer(root_uuid))
            .with_auto_layout(false)
            .with_auto_views(false),
    )?;
    bp_stream.log("blueprint_panel", &bp::PanelBlueprint::new().with_state(PanelState::Collapsed))?;
    bp_stream.log("selection_panel", &bp::PanelBlueprint::new().with_state(PanelState::Collapsed))?;
    bp_stream.log(
        "time_panel",
        &bp::TimePanelBlueprint::new()
            .with_state(PanelState::Collapsed)
            .with_timeline(bpc::TimelineName(playback.timeline.into()))
            .with_playback_speed(bpc::PlaybackSpeed(datatypes::Float64(playback.speed)))
            .with_play_state(if playback.follow { PlayState::Following } else { PlayState::Playing }),
    )?;
    // The memory sink is read after a flush; a flush failure only loses the layout, never data.
    let _ = bp_stream.flush_blocking();
    let msgs: Vec<LogMsg> = storage.take();
    let Some(blueprint_id) = msgs.first().map(|m| m.store_id().clone()) else {
        return Ok(());
    };
    rec.send_blueprint(msgs, BlueprintActivationCommand { blueprint_id, make_active: true, make_default: true });
    Ok(())
}
