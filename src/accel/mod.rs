//! Rays, ray–triangle intersection and a BVH over all scene triangles (camera rays, shadow
//! rays of the ray-cast oracle).
