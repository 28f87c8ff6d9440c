//! armscope's own protobuf messages in the MCAP (the controller's telemetry, the collision checks):
//! each a message of package `armscope` alone in its `.proto` file, its schema that file as MCAP's
//! protobuf profile wants it (a serialized FileDescriptorSet, which Foxglove and prost-reflect
//! decode the messages through).

use prost::Message;
use prost_types::field_descriptor_proto::{Label, Type};
use prost_types::{DescriptorProto, FieldDescriptorProto, FileDescriptorProto, FileDescriptorSet};

/// One field of a message: its name, number, whether repeated, and scalar type.
pub struct Field(pub &'static str, pub i32, pub bool, pub Type);

/// The schema of message `name` with `fields`, alone in `armscope/{file}.proto`.
pub fn file_descriptor_set(file: &str, name: &str, fields: &[Field]) -> Vec<u8> {
    let field = |Field(name, number, repeated, r#type): &Field| FieldDescriptorProto {
        name: Some((*name).into()),
        number: Some(*number),
        label: Some(if *repeated { Label::Repeated } else { Label::Optional } as i32),
        r#type: Some(*r#type as i32),
        json_name: Some((*name).into()),
        ..Default::default()
    };
    let message = DescriptorProto { name: Some(name.into()), field: fields.iter().map(field).collect(), ..Default::default() };
    let file = FileDescriptorProto {
        name: Some(format!("armscope/{file}.proto")),
        package: Some("armscope".into()),
        message_type: vec![message],
        syntax: Some("proto3".into()),
        ..Default::default()
    };
    FileDescriptorSet { file: vec![file] }.encode_to_vec()
}

/// `foxglove::Encode` for a prost message of this crate whose module has `SCHEMA_NAME` and
/// `file_descriptor_set()` (a blanket impl of the foreign trait is not allowed).
macro_rules! encode_as_protobuf {
    ($message:ty) => {
        impl foxglove::Encode for $message {
            type Error = prost::EncodeError;

            fn get_schema() -> Option<foxglove::Schema> {
                Some(foxglove::Schema::new(SCHEMA_NAME, "protobuf", file_descriptor_set()))
            }

            fn get_message_encoding() -> String {
                "protobuf".into()
            }

            fn encode(&self, buf: &mut impl bytes::BufMut) -> Result<(), Self::Error> {
                prost::Message::encode(self, buf)
            }

            fn encoded_len(&self) -> Option<usize> {
                Some(prost::Message::encoded_len(self))
            }
        }
    };
}
pub(super) use encode_as_protobuf;
