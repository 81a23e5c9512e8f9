// Copyright (c) 2025 Contributors to the Eclipse Foundation
//
// See the NOTICE file(s) distributed with this work for additional
// information regarding copyright ownership.
//
// This program and the accompanying materials are made available under the
// terms of the Apache Software License 2.0 which is available at
// https://www.apache.org/licenses/LICENSE-2.0, or the MIT license
// which is available at https://opensource.org/licenses/MIT.
//
// SPDX-License-Identifier: Apache-2.0 OR MIT

use iceoryx2_bb_concurrency::atomic::Ordering;

use alloc::boxed::Box;
use alloc::vec::Vec;

use core::sync::atomic::AtomicPtr;

use iceoryx2_bb_concurrency::atomic::{AtomicU64, AtomicUsize};

// PATCH(physics-service): a sender keeps a segment state for each of the 255 segments its
// dynamic data segment may grow to, and each held a reference counter per chunk, written at
// creation: 8.4 MB of heap for a publisher with 4,096 chunks a segment, 25 MB for a server
// with 12,288, nearly all for segments that never exist. The counters of a segment are now
// allocated when its first chunk is borrowed.
#[derive(Debug)]
pub(crate) struct SegmentState {
    /// The counters (`number_of_chunks` of them, boxed), or null before the first use.
    chunk_reference_counter: AtomicPtr<AtomicU64>,
    number_of_chunks: usize,
    payload_size: AtomicUsize,
}

impl Drop for SegmentState {
    fn drop(&mut self) {
        let counters = *self.chunk_reference_counter.get_mut();
        if !counters.is_null() {
            // SAFETY: a non-null pointer is a boxed slice of `number_of_chunks` counters
            // made by `counters` and owned by this state.
            drop(unsafe {
                Box::from_raw(core::ptr::slice_from_raw_parts_mut(
                    counters,
                    self.number_of_chunks,
                ))
            });
        }
    }
}

impl SegmentState {
    pub(crate) fn new(number_of_chunks: usize) -> Self {
        Self {
            chunk_reference_counter: AtomicPtr::new(core::ptr::null_mut()),
            number_of_chunks,
            payload_size: AtomicUsize::new(0),
        }
    }

    /// The segment's counters, allocated (zero) on first use.
    fn counters(&self) -> &[AtomicU64] {
        let mut counters = self.chunk_reference_counter.load(Ordering::Acquire);
        if counters.is_null() {
            let fresh: Box<[AtomicU64]> = (0..self.number_of_chunks)
                .map(|_| AtomicU64::new(0))
                .collect::<Vec<_>>()
                .into_boxed_slice();
            let fresh = Box::into_raw(fresh) as *mut AtomicU64;
            match self.chunk_reference_counter.compare_exchange(
                core::ptr::null_mut(),
                fresh,
                Ordering::AcqRel,
                Ordering::Acquire,
            ) {
                Ok(_) => counters = fresh,
                Err(theirs) => {
                    // SAFETY: `fresh` was made just above and never shared.
                    drop(unsafe {
                        Box::from_raw(core::ptr::slice_from_raw_parts_mut(
                            fresh,
                            self.number_of_chunks,
                        ))
                    });
                    counters = theirs;
                }
            }
        }
        // SAFETY: non-null, it points to `number_of_chunks` counters that live as long as
        // this state (freed only in `drop`).
        unsafe { core::slice::from_raw_parts(counters, self.number_of_chunks) }
    }

    pub(crate) fn set_payload_size(&self, value: usize) {
        self.payload_size.store(value, Ordering::Relaxed);
    }

    pub(crate) fn payload_size(&self) -> usize {
        self.payload_size.load(Ordering::Relaxed)
    }

    pub(crate) fn chunk_index(&self, distance_to_chunk: usize) -> usize {
        debug_assert!(distance_to_chunk.is_multiple_of(self.payload_size()));
        distance_to_chunk / self.payload_size()
    }

    pub(crate) fn borrow_chunk(&self, distance_to_chunk: usize) -> u64 {
        self.counters()[self.chunk_index(distance_to_chunk)].fetch_add(1, Ordering::Relaxed)
    }

    pub(crate) fn release_chunk(&self, distance_to_chunk: usize) -> u64 {
        self.counters()[self.chunk_index(distance_to_chunk)].fetch_sub(1, Ordering::Relaxed)
    }
}
