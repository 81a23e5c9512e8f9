// Copyright (c) 2023 Contributors to the Eclipse Foundation
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

//! [`SharedMemory`] based implementation of a [`DynamicStorage`].
//!
//! # Example
//!
//! ```
//! # extern crate iceoryx2_bb_loggers;
//!
//! use iceoryx2_bb_concurrency::atomic::{AtomicI64, Ordering};
//! use iceoryx2_bb_posix::access_mode::AccessMode;
//! use iceoryx2_bb_system_types::file_name::FileName;
//! use iceoryx2_bb_container::semantic_string::SemanticString;
//! use iceoryx2_cal::dynamic_storage::posix_shared_memory::*;
//! use iceoryx2_cal::named_concept::*;
//!
//! let additional_size: usize = 1024;
//! let storage_name = FileName::new(b"myStorageName").unwrap();
//! let owner = Builder::new(&storage_name)
//!                 .supplementary_size(additional_size)
//!                 // we always have to use a thread-safe object since multiple processes can
//!                 // access this concurrently
//!                 .initializer(|value, _| {
//!                     value.write(AtomicI64::new(0));
//!                     true
//!                 })
//!                 .create()
//!                 .unwrap();
//! owner.get().store(123, Ordering::Relaxed);
//!
//! // usually a different process
//! let storage = Builder::<AtomicI64>::new(&storage_name)
//!                 .open(AccessMode::ReadWrite).unwrap();
//!
//! println!("Initial value: {}", storage.get().load(Ordering::Relaxed));
//! // returns a reference to the underlying atomic
//! storage.get().store(456, Ordering::Relaxed);
//!
//! ```
pub use crate::dynamic_storage::*;
pub use core::ops::Deref;

use core::fmt::Debug;
use core::marker::PhantomData;
use core::ptr::NonNull;
use core::time::Duration;
use iceoryx2_bb_concurrency::atomic::Ordering;

use alloc::format;
use alloc::string::String;
use alloc::string::ToString;
use alloc::vec;
use alloc::vec::Vec;

use iceoryx2_bb_concurrency::atomic::AtomicU64;
use iceoryx2_bb_elementary::package_version::PackageVersion;
use iceoryx2_bb_posix::adaptive_wait::{AdaptiveWaitBuilder, AdaptiveWaitStrategy};
use iceoryx2_bb_posix::directory::*;
use iceoryx2_bb_posix::file_descriptor::FileDescriptorManagement;
use iceoryx2_bb_posix::memory_mapping::MemoryMappingCreationError;
use iceoryx2_bb_posix::shared_memory::*;
use iceoryx2_bb_system_types::path::Path;
use iceoryx2_log::fail;

use crate::static_storage::file::NamedConceptConfiguration;
use crate::static_storage::file::NamedConceptRemoveError;

use self::dynamic_storage_configuration::DynamicStorageConfiguration;

const INIT_PERMISSIONS: Permission = Permission::OWNER_WRITE;

#[cfg(not(feature = "dev_permissions"))]
const FINAL_PERMISSIONS: Permission = Permission::OWNER_READ_WRITE;

const FINAL_PERMISSIONS_GLOBAL_ACCESS: Permission = Permission::OWNER_READ_WRITE
    .const_bitor(Permission::GROUP_READ_WRITE)
    .const_bitor(Permission::OTHERS_READ_WRITE);

#[cfg(feature = "dev_permissions")]
const FINAL_PERMISSIONS: Permission = FINAL_PERMISSIONS_GLOBAL_ACCESS;

/// The builder of [`Storage`].
#[derive(Debug)]
pub struct Builder<'builder, T: Send + Sync + Debug + ZeroCopySend> {
    storage_name: FileName,
    supplementary_size: usize,
    enable_global_access: bool,
    has_ownership: bool,
    config: Configuration<T>,
    timeout: Duration,
    initializer: Initializer<'builder, T>,
    _phantom_data: PhantomData<T>,
}

#[derive(Debug)]
pub struct Configuration<T: Send + Sync + Debug + ZeroCopySend> {
    suffix: FileName,
    prefix: FileName,
    path: Path,
    _data: PhantomData<T>,
    type_name: String,
}

impl<T: Send + Sync + Debug + ZeroCopySend> Clone for Configuration<T> {
    fn clone(&self) -> Self {
        Self {
            suffix: self.suffix,
            prefix: self.prefix,
            path: self.path,
            _data: PhantomData,
            type_name: self.type_name.clone(),
        }
    }
}

#[repr(C)]
struct Data<T: Send + Sync + Debug + ZeroCopySend> {
    version: AtomicU64,
    data: MaybeUninit<T>,
}

impl<T: Send + Sync + Debug + ZeroCopySend> Default for Configuration<T> {
    fn default() -> Self {
        Self {
            path: Storage::<()>::default_path_hint(),
            suffix: Storage::<()>::default_suffix(),
            prefix: Storage::<()>::default_prefix(),
            _data: PhantomData,
            type_name: core::any::type_name::<T>().to_string(),
        }
    }
}

impl<T: Send + Sync + Debug + ZeroCopySend> DynamicStorageConfiguration for Configuration<T> {
    fn type_name(&self) -> &str {
        &self.type_name
    }
}

impl<T: Send + Sync + Debug + ZeroCopySend> NamedConceptConfiguration for Configuration<T> {
    fn prefix(mut self, value: &FileName) -> Self {
        self.prefix = *value;
        self
    }

    fn get_prefix(&self) -> &FileName {
        &self.prefix
    }

    fn suffix(mut self, value: &FileName) -> Self {
        self.suffix = *value;
        self
    }

    fn path_hint(mut self, value: &Path) -> Self {
        self.path = *value;
        self
    }

    fn get_suffix(&self) -> &FileName {
        &self.suffix
    }

    fn get_path_hint(&self) -> &Path {
        &self.path
    }

    fn path_for(&self, value: &FileName) -> iceoryx2_bb_system_types::file_path::FilePath {
        self.path_for_with_type(value)
    }

    fn extract_name_from_file(&self, value: &FileName) -> Option<FileName> {
        self.extract_name_from_file_with_type(value)
    }
}

impl<T: Send + Sync + Debug + ZeroCopySend> NamedConceptBuilder<Storage<T>> for Builder<'_, T> {
    fn new(storage_name: &FileName) -> Self {
        Self {
            has_ownership: true,
            storage_name: *storage_name,
            supplementary_size: 0,
            config: Configuration::default(),
            enable_global_access: false,
            timeout: Duration::ZERO,
            initializer: Initializer::new(|_, _| false),
            _phantom_data: PhantomData,
        }
    }

    fn config(mut self, config: &Configuration<T>) -> Self {
        self.config = config.clone();
        self
    }
}

impl<T: Send + Sync + Debug + ZeroCopySend> Builder<'_, T> {
    fn open_impl(&self, access_mode: AccessMode) -> Result<Storage<T>, DynamicStorageOpenError> {
        let msg = "Failed to open posix_shared_memory::DynamicStorage";

        let full_name = self.config.path_for(&self.storage_name).file_name();
        let mut wait_for_read_write_access = fail!(from self,
                                    when AdaptiveWaitBuilder::new()
                                        .strategy(AdaptiveWaitStrategy::FixedTicks(Duration::from_millis(1))).create(),
                                    with DynamicStorageOpenError::InternalError,
                                    "{} since the AdaptiveWait could not be initialized.", msg);

        let mut elapsed_time = Duration::ZERO;
        let shm = loop {
            match SharedMemoryBuilder::new(&full_name).open_existing(access_mode) {
                Ok(v) => {
                    let permissions = match v.permission() {
                        Ok(p) => p,
                        Err(e) => {
                            fail!(from self, with DynamicStorageOpenError::InternalError, "{} since a failure occurred while acquiring the file permissions. Error: {:?}", msg, e);
                        }
                    };
                    // NOTE: although the shm is opened for reading, root can still open a write-only shm;
                    // when this happens, the subsequent read will cause a SIGBUS
                    if permissions.has(Permission::OWNER_READ) {
                        break v;
                    }

                    if elapsed_time >= self.timeout {
                        fail!(from self, with DynamicStorageOpenError::InitializationNotYetFinalized,
                                  "{} since it is not readable - (it is not initialized after {:?}).",
                                  msg, self.timeout);
                    }
                }
                Err(SharedMemoryCreationError::DoesNotExist) => {
                    fail!(from self, with DynamicStorageOpenError::DoesNotExist,
                    "{} since a shared memory with that name does not exists.", msg);
                }
                Err(SharedMemoryCreationError::InsufficientPermissions) => {
                    if elapsed_time >= self.timeout {
                        fail!(from self, with DynamicStorageOpenError::InitializationNotYetFinalized,
                        "{} since it is not readable - (it is not initialized after {:?}).",
                        msg, self.timeout);
                    }
                }
                Err(SharedMemoryCreationError::MemoryMappingCreationError(
                    MemoryMappingCreationError::MappingSizeIsZero,
                )) => (),
                Err(e) => {
                    fail!(from self, with DynamicStorageOpenError::InternalError, "{} since the underlying shared memory could not be opened. Error: {:?}", msg, e);
                }
            };

            elapsed_time = fail!(from self, when wait_for_read_write_access.wait(),
                                    with DynamicStorageOpenError::InternalError,
                                    "{} since the adaptive wait call failed.", msg);
        };

        let init_state = shm.base_address().as_ptr() as *const Data<T>;

        loop {
            // The mem-sync is actually not required since an uninitialized dynamic storage has
            // only write permissions and can be therefore not consumed.
            // This is only for the case that this strategy fails on an obscure POSIX platform.
            //
            //////////////////////////////////////////
            // SYNC POINT: read Data<T>::data
            //////////////////////////////////////////
            let package_version = unsafe { &(*init_state) }
                .version
                .load(core::sync::atomic::Ordering::SeqCst);

            let package_version = PackageVersion::from_u64(package_version);
            if package_version.to_u64() == 0 {
                if elapsed_time >= self.timeout {
                    fail!(from self, with DynamicStorageOpenError::InitializationNotYetFinalized,
                        "{} since the version number was not set - (it is not initialized after {:?}).",
                        msg, self.timeout);
                }
            } else if package_version != PackageVersion::get() {
                fail!(from self, with DynamicStorageOpenError::VersionMismatch,
                       "{} since the dynamic storage was created with version {} but this process requires version {}.",
                        msg, package_version, PackageVersion::get());
            } else {
                break;
            }

            elapsed_time = fail!(from self, when wait_for_read_write_access.wait(),
                                    with DynamicStorageOpenError::InternalError,
                                    "{} since the adaptive wait call failed.", msg);
        }

        Ok(Storage {
            shm,
            name: self.storage_name,
            _phantom_data: PhantomData,
        })
    }

    fn create_impl(&mut self) -> Result<SharedMemory, DynamicStorageCreateError> {
        let msg = "Failed to create dynamic_storage::PosixSharedMemory";

        let full_name = self.config.path_for(&self.storage_name).file_name();
        let shm = match SharedMemoryBuilder::new(&full_name)
            .creation_mode(CreationMode::CreateExclusive)
            // posix shared memory is always aligned to the greatest possible value (PAGE_SIZE)
            // therefore we do not have to add additional alignment space for T
            .size(core::mem::size_of::<Data<T>>() + self.supplementary_size)
            .permission(INIT_PERMISSIONS)
            .zero_memory(false)
            .has_ownership(self.has_ownership)
            .create()
        {
            Ok(v) => v,
            Err(SharedMemoryCreationError::AlreadyExist) => {
                fail!(from self, with DynamicStorageCreateError::AlreadyExists,
                    "{} since a shared memory with the name already exists.", msg);
            }
            Err(SharedMemoryCreationError::InsufficientPermissions) => {
                fail!(from self, with DynamicStorageCreateError::InsufficientPermissions,
                    "{} due to insufficient permissions.", msg);
            }
            Err(_) => {
                fail!(from self, with DynamicStorageCreateError::InternalError,
                    "{} since the underlying shared memory could not be created.", msg);
            }
        };

        Ok(shm)
    }

    fn init_impl(
        &mut self,
        mut shm: SharedMemory,
    ) -> Result<Storage<T>, DynamicStorageCreateError> {
        let msg = "Failed to init dynamic_storage::PosixSharedMemory";
        let value = shm.base_address().as_ptr() as *mut Data<T>;
        let version_ptr = unsafe { core::ptr::addr_of_mut!((*value).version) };
        unsafe { version_ptr.write(AtomicU64::new(0)) };

        unsafe { core::ptr::addr_of_mut!((*value).data).write(MaybeUninit::uninit()) };

        let supplementary_start =
            (shm.base_address().as_ptr() as usize + core::mem::size_of::<Data<T>>()) as *mut u8;
        let supplementary_len = shm.size() - core::mem::size_of::<Data<T>>();

        let mut allocator = BumpAllocator::new(
            unsafe { NonNull::new_unchecked(supplementary_start) },
            supplementary_len,
        );

        let origin = format!("{self:?}");
        if !self
            .initializer
            .call(unsafe { &mut (*value).data }, &mut allocator)
        {
            unsafe { core::ptr::drop_in_place(value) };
            shm.acquire_ownership();
            fail!(from origin, with DynamicStorageCreateError::InitializationFailed,
                "{} since the initialization of the underlying construct failed.", msg);
        }

        // The mem-sync is actually not required since an uninitialized dynamic storage has
        // only write permissions and can be therefore not consumed.
        // This is only for the case that this strategy fails on an obscure POSIX platform.
        //
        //////////////////////////////////////////
        // SYNC POINT: write Data<T>::data
        //////////////////////////////////////////
        unsafe { (*version_ptr).store(PackageVersion::get().to_u64(), Ordering::SeqCst) };

        let final_permission = if self.enable_global_access {
            FINAL_PERMISSIONS_GLOBAL_ACCESS
        } else {
            FINAL_PERMISSIONS
        };

        if let Err(e) = shm.set_permission(final_permission) {
            unsafe { core::ptr::drop_in_place(value) };
            shm.acquire_ownership();
            fail!(from origin, with DynamicStorageCreateError::InternalError,
                "{} since the final permissions could not be applied to the underlying shared memory ({:?}).",
                msg, e);
        }

        Ok(Storage {
            shm,
            name: self.storage_name,
            _phantom_data: PhantomData,
        })
    }
}

impl<'builder, T: Send + Sync + Debug + ZeroCopySend> DynamicStorageBuilder<'builder, T, Storage<T>>
    for Builder<'builder, T>
{
    fn has_ownership(mut self, value: bool) -> Self {
        self.has_ownership = value;
        self
    }

    fn enable_global_access(mut self, value: bool) -> Self {
        self.enable_global_access = value;
        self
    }

    fn initializer<F: FnMut(&mut MaybeUninit<T>, &mut BumpAllocator) -> bool + 'builder>(
        mut self,
        value: F,
    ) -> Self {
        self.initializer = Initializer::new(value);
        self
    }

    fn timeout(mut self, value: Duration) -> Self {
        self.timeout = value;
        self
    }

    fn supplementary_size(mut self, value: usize) -> Self {
        self.supplementary_size = value;
        self
    }

    fn create(mut self) -> Result<Storage<T>, DynamicStorageCreateError> {
        let shm = self.create_impl()?;
        self.init_impl(shm)
    }

    fn open(self, access_mode: AccessMode) -> Result<Storage<T>, DynamicStorageOpenError> {
        self.open_impl(access_mode)
    }

    fn open_or_create(mut self) -> Result<Storage<T>, DynamicStorageOpenOrCreateError> {
        loop {
            match self.open_impl(AccessMode::ReadWrite) {
                Ok(storage) => return Ok(storage),
                Err(DynamicStorageOpenError::DoesNotExist) => match self.create_impl() {
                    Ok(shm) => {
                        return Ok(self.init_impl(shm)?);
                    }
                    Err(DynamicStorageCreateError::AlreadyExists) => continue,
                    Err(e) => return Err(e.into()),
                },
                Err(e) => return Err(e.into()),
            }
        }
    }
}

/// Implements [`DynamicStorage`] for POSIX shared memory. It is built by
/// [`Builder`].
#[derive(Debug)]
pub struct Storage<T: Debug + Send + Sync + ZeroCopySend> {
    shm: SharedMemory,
    name: FileName,
    _phantom_data: PhantomData<T>,
}

unsafe impl<T: Debug + Send + Sync + ZeroCopySend> Send for Storage<T> {}
unsafe impl<T: Debug + Send + Sync + ZeroCopySend> Sync for Storage<T> {}

impl<T: Debug + Send + Sync + ZeroCopySend> Abandonable for Storage<T> {
    unsafe fn abandon_in_place(mut this: NonNull<Self>) {
        let this = unsafe { this.as_mut() };
        unsafe { SharedMemory::abandon_in_place(NonNull::from_mut(&mut this.shm)) };
    }
}

impl<T: Debug + Send + Sync + ZeroCopySend> Drop for Storage<T> {
    fn drop(&mut self) {
        if self.shm.has_ownership() {
            let user_type =
                unsafe { &mut (*(self.shm.base_address().as_ptr() as *mut Data<T>)).data };
            unsafe { core::ptr::drop_in_place(user_type) };
        }
    }
}

impl<T: Send + Sync + Debug + ZeroCopySend> NamedConcept for Storage<T> {
    fn name(&self) -> &FileName {
        &self.name
    }
}

impl<T: Send + Sync + Debug + ZeroCopySend> NamedConceptMgmt for Storage<T> {
    type Configuration = Configuration<T>;

    fn does_exist_cfg(
        name: &FileName,
        cfg: &Self::Configuration,
    ) -> Result<bool, crate::static_storage::file::NamedConceptDoesExistError> {
        let full_name = cfg.path_for(name).file_name();

        Ok(iceoryx2_bb_posix::shared_memory::SharedMemory::does_exist(
            &full_name,
        ))
    }

    fn list_cfg(
        config: &Self::Configuration,
    ) -> Result<Vec<FileName>, crate::static_storage::file::NamedConceptListError> {
        let entries = SharedMemory::list();

        let mut result = vec![];
        for entry in &entries {
            if let Some(entry_name) = config.extract_name_from_file(entry) {
                result.push(entry_name);
            }
        }

        Ok(result)
    }

    unsafe fn remove_cfg(
        name: &FileName,
        cfg: &Self::Configuration,
    ) -> Result<bool, crate::static_storage::file::NamedConceptRemoveError> {
        let full_name = cfg.path_for(name).file_name();
        let msg = "Unable to remove dynamic_storage::posix_shared_memory";
        let origin = "dynamic_storage::posix_shared_memory::Storage::remove_cfg()";

        match iceoryx2_bb_posix::shared_memory::SharedMemory::remove(&full_name) {
            Ok(v) => Ok(v),
            Err(
                iceoryx2_bb_posix::shared_memory::SharedMemoryRemoveError::InsufficientPermissions,
            ) => {
                fail!(from origin, with NamedConceptRemoveError::InsufficientPermissions,
                                     "{} \"{}\" due to insufficient permissions.", msg, name);
            }
            Err(v) => {
                fail!(from origin, with NamedConceptRemoveError::InternalError,
                                    "{} \"{}\" due to an internal failure ({:?}).", msg, name, v);
            }
        }
    }

    fn remove_path_hint(
        _value: &Path,
    ) -> Result<(), crate::named_concept::NamedConceptPathHintRemoveError> {
        Ok(())
    }
}

impl<T: Send + Sync + Debug + ZeroCopySend> DynamicStorage<T> for Storage<T> {
    type Builder<'builder> = Builder<'builder, T>;

    // PATCH(physics-service): a storage is created exclusively (a new POSIX shared memory
    // object) and sized with ftruncate, so its memory reads as zeros until written.
    const CREATES_ZEROED_MEMORY: bool = true;

    fn does_support_persistency() -> bool {
        SharedMemory::does_support_persistency()
    }

    fn acquire_ownership(&self) {
        self.shm.acquire_ownership()
    }

    fn get(&self) -> &T {
        unsafe {
            (*(self.shm.base_address().as_ptr() as *const Data<T>))
                .data
                .assume_init_ref()
        }
    }

    fn has_ownership(&self) -> bool {
        self.shm.has_ownership()
    }

    fn release_ownership(&self) {
        self.shm.release_ownership()
    }

    unsafe fn __internal_set_type_name_in_config(
        config: &mut Self::Configuration,
        type_name: &str,
    ) {
        config.type_name = type_name.to_string()
    }
}
