//! `/robot_description`: the URDF text as ROS 2's `std_msgs/msg/String` (ros2msg schema, CDR), the
//! convention by which Foxglove's URDF layer and Rerun's MCAP importer find the robot by themselves.

use bytes::BufMut;
use foxglove::{Encode, Schema};

pub const SCHEMA_NAME: &str = "std_msgs/msg/String";

/// The URDF text.
#[derive(Clone, Debug)]
pub struct RobotDescription {
    pub data: String,
}

impl Encode for RobotDescription {
    type Error = std::convert::Infallible;

    fn get_schema() -> Option<Schema> {
        Some(Schema::new(SCHEMA_NAME, "ros2msg", b"string data".as_slice()))
    }

    fn get_message_encoding() -> String {
        "cdr".into()
    }

    /// CDR, little endian: the 4-byte encapsulation header, then the string as its length with the
    /// terminating NUL, its bytes and the NUL.
    fn encode(&self, buf: &mut impl BufMut) -> Result<(), Self::Error> {
        buf.put_slice(&[0x00, 0x01, 0x00, 0x00]);
        buf.put_u32_le(self.data.len() as u32 + 1);
        buf.put_slice(self.data.as_bytes());
        buf.put_u8(0);
        Ok(())
    }

    fn encoded_len(&self) -> Option<usize> {
        Some(4 + 4 + self.data.len() + 1)
    }
}

/// The text of a CDR-encoded `std_msgs/msg/String`, or `None` if `bytes` is not one.
pub fn decode(bytes: &[u8]) -> Option<&str> {
    let (header, rest) = bytes.split_at_checked(4)?;
    if header[..2] != [0x00, 0x01] {
        return None; // only little-endian plain CDR is written here
    }
    let (len, rest) = rest.split_at_checked(4)?;
    let len = u32::from_le_bytes(len.try_into().ok()?) as usize;
    let text = rest.get(..len)?.strip_suffix(&[0])?;
    std::str::from_utf8(text).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cdr_string_round_trips_with_its_length_and_terminator() {
        let msg = RobotDescription { data: "<robot name=\"r\"/>".into() };
        let mut bytes = Vec::new();
        msg.encode(&mut bytes).unwrap();
        assert_eq!(bytes.len(), msg.encoded_len().unwrap());
        assert_eq!(&bytes[..8], &[0, 1, 0, 0, 18, 0, 0, 0], "CDR_LE header, length 17 + NUL");
        assert_eq!(decode(&bytes), Some("<robot name=\"r\"/>"));
        assert_eq!(decode(&bytes[..bytes.len() - 1]), None, "a cut message is not read");
    }
}
