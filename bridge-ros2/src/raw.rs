//! A DDS sample's bytes as they came, encapsulation header included: the
//! reader type of the bridge's topics and of its service replies. The map's
//! decoder ([`situ_ros2_map::cdr`]) reads them, not serde.

use rustdds::no_key;
use rustdds::RepresentationIdentifier;
use std::fmt;

/// A sample's bytes as they came, encapsulation header included: the
/// map's decoder ([`situ_ros2_map::cdr`]) reads them, not serde.
pub struct Raw(pub Vec<u8>);

/// The adapter that keeps a sample's bytes.
pub struct RawAdapter;

#[derive(Debug)]
pub struct Never;

impl fmt::Display for Never {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("never")
    }
}

impl std::error::Error for Never {}

/// Every encapsulation RTPS and XTypes name (XCDR2 is `00 06`/`00 07`,
/// its delimited and parameter-list forms `00 08` to `00 0b`; RustDDS's
/// `CDR2_LE` is `00 11`): one the map's decoder does not read is refused
/// and counted there, not dropped by RustDDS unseen. A sample of another
/// identifier fails `take`, which the loop counts as refused.
const ENCODINGS: [RepresentationIdentifier; 17] = {
    use RepresentationIdentifier as R;
    [
        R::CDR_BE,
        R::CDR_LE,
        R::PL_CDR_BE,
        R::PL_CDR_LE,
        R::XML,
        R::XCDR2_BE,
        R::XCDR2_LE,
        R::D_CDR2_BE,
        R::D_CDR2_LE,
        R::PL_XCDR2_BE,
        R::PL_XCDR2_LE,
        R::CDR2_BE,
        R::CDR2_LE,
        R::PL_CDR2_BE,
        R::PL_CDR2_LE,
        R::D_CDR_BE,
        R::D_CDR_LE,
    ]
};

impl no_key::DeserializerAdapter<Raw> for RawAdapter {
    type Error = Never;
    type Decoded = Raw;

    fn supported_encodings() -> &'static [RepresentationIdentifier] {
        &ENCODINGS
    }

    fn transform_decoded(decoded: Raw) -> Raw {
        decoded
    }
}

#[derive(Clone)]
pub struct RawDecoder;

impl<'de> no_key::Decode<'de, Raw> for RawDecoder {
    type Error = Never;

    fn decode_bytes(self, input: &'de [u8], encoding: RepresentationIdentifier) -> Result<Raw, Never> {
        let mut bytes = Vec::with_capacity(4 + input.len());
        bytes.extend(encoding.to_bytes());
        bytes.extend([0, 0]);
        bytes.extend_from_slice(input);
        Ok(Raw(bytes))
    }
}

impl no_key::DefaultDecoder<Raw> for RawAdapter {
    type Decoder = RawDecoder;
    const DECODER: RawDecoder = RawDecoder;
}
