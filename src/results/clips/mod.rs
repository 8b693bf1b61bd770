//! What `lodbench clips` (`commands/clips.rs`) makes of a run's frame dumps: the pictures (`compose.rs`: crop,
//! upscale, text, legend, grids) and the files they are written as (`encode.rs`: PNG, APNG, GIF, MP4).

pub mod compose;
pub mod encode;
