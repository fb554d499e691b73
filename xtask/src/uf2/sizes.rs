//! The two sizes of a UF2 file the writer, the reader and their errors
//! share.

/// Size of a block.
pub const BLOCK_SIZE: usize = 512;
/// Bytes of each block's data that the RP2040 and RP2350 boot ROMs write:
/// one flash page, at a page-aligned address.
pub const PAYLOAD_SIZE: u32 = 256;
