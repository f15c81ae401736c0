//! Frictional contact with recoverable adhesion: the local law (pure functions).

pub mod law;
