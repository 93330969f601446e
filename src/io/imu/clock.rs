//! Time stamps as written in a log and as seconds since its first: units, nanosecond stamps kept
//! exact as integers, GPS seconds of week with their rollover.

/// Seconds in a GPS week.
pub const GPS_WEEK_S: f64 = 604_800.0;

/// The unit of a time column.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimeUnit {
    /// Seconds.
    Seconds,
    /// Milliseconds.
    Milliseconds,
    /// Microseconds.
    Microseconds,
    /// Nanoseconds (integer stamps are kept exact).
    Nanoseconds,
    /// GPS seconds of week, with week rollover.
    GpsSecondsOfWeek,
}

impl TimeUnit {
    pub(crate) fn to_s(self) -> f64 {
        match self {
            Self::Seconds | Self::GpsSecondsOfWeek => 1.0,
            Self::Milliseconds => 1e-3,
            Self::Microseconds => 1e-6,
            Self::Nanoseconds => 1e-9,
        }
    }
    pub(crate) fn ns_per_unit(self) -> Option<i64> {
        match self {
            Self::Milliseconds => Some(1_000_000),
            Self::Microseconds => Some(1_000),
            Self::Nanoseconds => Some(1),
            Self::Seconds | Self::GpsSecondsOfWeek => None,
        }
    }
    pub(crate) fn symbol(self) -> &'static str {
        match self {
            Self::Seconds => "s",
            Self::Milliseconds => "ms",
            Self::Microseconds => "us",
            Self::Nanoseconds => "ns",
            Self::GpsSecondsOfWeek => "s of GPS week",
        }
    }
}

/// The first time stamp of a stream, as written in the file.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StartTime {
    /// Seconds (or ms/us converted to s when not integers).
    Seconds(f64),
    /// Integer nanoseconds (exact).
    Nanoseconds(i64),
    /// GPS seconds of week.
    GpsSecondsOfWeek(f64),
}

/// A time stamp as written (formatted only for an error message: the hot path stays free of
/// allocation).
#[derive(Debug, Clone, Copy)]
pub(crate) struct RawStamp {
    pub(crate) value: f64,
    pub(crate) exact: Option<i64>,
    pub(crate) unit: TimeUnit,
}

impl std::fmt::Display for RawStamp {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.exact {
            Some(int) => write!(f, "{int} {}", self.unit.symbol()),
            None => write!(f, "{} {}", crate::io::error::short_number(self.value), self.unit.symbol()),
        }
    }
}

/// Converts raw time stamps to seconds since the first, in order.
pub(crate) struct Clock {
    pub(crate) unit: TimeUnit,
    pub(crate) first_ns: Option<i64>,
    pub(crate) first: Option<f64>,
    pub(crate) prev_sow: f64,
    pub(crate) week_offset_s: f64,
}

impl Clock {
    pub(crate) fn convert(&mut self, value: f64, exact: Option<i64>) -> (f64, RawStamp) {
        if let (Some(per), Some(int)) = (self.unit.ns_per_unit(), exact)
            && let Some(ns) = int.checked_mul(per)
        {
            let first = *self.first_ns.get_or_insert(ns);
            self.first.get_or_insert(value);
            let t = (i128::from(ns) - i128::from(first)) as f64 * 1e-9;
            return (t, RawStamp { value, exact: Some(int), unit: self.unit });
        }
        let first = *self.first.get_or_insert(value);
        let raw = RawStamp { value, exact: None, unit: self.unit };
        if self.unit == TimeUnit::GpsSecondsOfWeek {
            if self.prev_sow - value > GPS_WEEK_S / 2.0 {
                self.week_offset_s += GPS_WEEK_S;
            }
            self.prev_sow = value;
            return (value + self.week_offset_s - first, raw);
        }
        (self.since(first, value), raw)
    }

    /// A stamp `value` in seconds after the first stamp `first` (decimal units: no state).
    #[inline]
    pub(crate) fn since(&self, first: f64, value: f64) -> f64 {
        (value - first) * self.unit.to_s()
    }

    /// The first stamp, once known, if every later stamp converts without state ([`Self::since`]):
    /// neither GPS seconds of week (rollovers) nor exact integers.
    pub(crate) fn stateless_origin(&self) -> Option<f64> {
        self.first.filter(|_| self.first_ns.is_none() && self.unit != TimeUnit::GpsSecondsOfWeek)
    }

    pub(crate) fn start(&self) -> Option<StartTime> {
        match (self.first_ns, self.first) {
            (Some(ns), _) => Some(StartTime::Nanoseconds(ns)),
            (None, Some(v)) if self.unit == TimeUnit::GpsSecondsOfWeek => Some(StartTime::GpsSecondsOfWeek(v)),
            (None, Some(v)) => Some(StartTime::Seconds(v * self.unit.to_s())),
            (None, None) => None,
        }
    }
}
