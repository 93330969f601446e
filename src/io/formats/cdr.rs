//! Hand-written CDR decoding of ROS 2 `sensor_msgs/msg/Imu`.
//!
//! A ROS 2 message in MCAP (`message_encoding: cdr`) is a 4-byte encapsulation header
//! (`00 01 00 00` = little-endian CDR, `00 00 00 00` = big-endian CDR) followed by the fields in
//! order, each aligned to its own size (f64 to 8 bytes) counted from the end of the encapsulation
//! header. `sensor_msgs/msg/Imu` is:
//!
//! ```text
//! std_msgs/Header header
//!     builtin_interfaces/Time stamp { int32 sec, uint32 nanosec }
//!     string frame_id                     (uint32 length incl. NUL, bytes, NUL)
//! geometry_msgs/Quaternion orientation    (x, y, z, w: f64)
//! float64[9] orientation_covariance
//! geometry_msgs/Vector3 angular_velocity  (x, y, z: f64, rad/s)
//! float64[9] angular_velocity_covariance
//! geometry_msgs/Vector3 linear_acceleration (x, y, z: f64, m/s²)
//! float64[9] linear_acceleration_covariance
//! ```
//!
//! By the message's definition a covariance whose element 0 is −1 means "this quantity is not
//! provided"; we refuse such messages for angular velocity and linear acceleration.

/// The fields of an Imu message that an IMU log needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ImuMessage {
    pub stamp_sec: i32,
    pub stamp_nanosec: u32,
    pub angular_velocity: [f64; 3],
    pub linear_acceleration: [f64; 3],
}

struct Cursor<'a> {
    data: &'a [u8],
    pos: usize,
    little: bool,
}

impl<'a> Cursor<'a> {
    fn align(&mut self, n: usize) {
        self.pos = self.pos.div_ceil(n) * n;
    }

    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], String> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.data.len());
        let Some(end) = end else {
            return Err(format!("message ends inside {what} (byte {} of {})", self.pos + 4, self.data.len() + 4));
        };
        let bytes = self.data.get(self.pos..end).ok_or_else(|| format!("message ends inside {what}"))?;
        self.pos = end;
        Ok(bytes)
    }

    fn u32(&mut self, what: &str) -> Result<u32, String> {
        self.align(4);
        let b: [u8; 4] = self.take(4, what)?.try_into().map_err(|_| what.to_owned())?;
        Ok(if self.little { u32::from_le_bytes(b) } else { u32::from_be_bytes(b) })
    }

    fn f64(&mut self, what: &str) -> Result<f64, String> {
        self.align(8);
        let b: [u8; 8] = self.take(8, what)?.try_into().map_err(|_| what.to_owned())?;
        Ok(if self.little { f64::from_le_bytes(b) } else { f64::from_be_bytes(b) })
    }

    fn f64s<const N: usize>(&mut self, what: &str) -> Result<[f64; N], String> {
        let mut out = [0.0; N];
        for v in &mut out {
            *v = self.f64(what)?;
        }
        Ok(out)
    }
}

/// Decodes a CDR-encoded `sensor_msgs/msg/Imu`; the error says what is wrong.
pub(crate) fn decode_imu(message: &[u8]) -> Result<ImuMessage, String> {
    let (Some(header), Some(data)) = (message.get(..4), message.get(4..)) else {
        return Err(format!("{} bytes: shorter than the 4-byte CDR encapsulation header", message.len()));
    };
    let little = match header {
        [0, 1, _, _] => true,
        [0, 0, _, _] => false,
        _ => {
            return Err(format!(
                "encapsulation {:02x} {:02x} is not plain CDR (00 01 little-endian or 00 00 big-endian)",
                header[0], header[1]
            ));
        }
    };
    let mut c = Cursor { data, pos: 0, little };
    let stamp_sec = c.u32("header.stamp.sec")?.cast_signed();
    let stamp_nanosec = c.u32("header.stamp.nanosec")?;
    let frame_len = c.u32("header.frame_id length")? as usize;
    c.take(frame_len, "header.frame_id")?;
    let _orientation: [f64; 4] = c.f64s("orientation")?;
    let _orientation_cov: [f64; 9] = c.f64s("orientation_covariance")?;
    let angular_velocity: [f64; 3] = c.f64s("angular_velocity")?;
    let angular_velocity_cov: [f64; 9] = c.f64s("angular_velocity_covariance")?;
    let linear_acceleration: [f64; 3] = c.f64s("linear_acceleration")?;
    let linear_acceleration_cov: [f64; 9] = c.f64s("linear_acceleration_covariance")?;
    if angular_velocity_cov[0] == -1.0 {
        return Err("angular_velocity_covariance[0] is -1: the message has no angular velocity".into());
    }
    if linear_acceleration_cov[0] == -1.0 {
        return Err("linear_acceleration_covariance[0] is -1: the message has no linear acceleration".into());
    }
    if stamp_nanosec >= 1_000_000_000 {
        return Err(format!("header.stamp.nanosec = {stamp_nanosec} is not below 1e9"));
    }
    Ok(ImuMessage { stamp_sec, stamp_nanosec, angular_velocity, linear_acceleration })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_and_foreign_messages_are_errors() {
        assert!(decode_imu(&[]).is_err());
        assert!(decode_imu(&[0, 1, 0, 0]).is_err());
        assert!(decode_imu(&[0, 7, 0, 0, 1, 2, 3, 4]).is_err());
        // A frame_id length of 4 GiB must not be trusted.
        let mut m = vec![0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0];
        m.extend_from_slice(&u32::MAX.to_le_bytes());
        assert!(decode_imu(&m).is_err());
    }
}
