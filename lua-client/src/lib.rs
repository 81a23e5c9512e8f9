//! The documented Luau `PhysicsService` API on top of client-sdk (in progress).
