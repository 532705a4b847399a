// Made from server/api/openapi.json by openapi-typescript (npm run gen:api-types
// in web/): do not edit; change the document and run it again.

export interface paths {
    "/api/health": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** Liveness */
        get: {
            parameters: {
                query?: never;
                header?: never;
                path?: never;
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description the server runs */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": Record<string, unknown>;
                    };
                };
            };
        };
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/openapi.json": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** This API description */
        get: {
            parameters: {
                query?: never;
                header?: never;
                path?: never;
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description OpenAPI 3 document */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": Record<string, unknown>;
                    };
                };
            };
        };
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/login": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        get?: never;
        put?: never;
        /** Log in (staff) */
        post: {
            parameters: {
                query?: never;
                header?: never;
                path?: never;
                cookie?: never;
            };
            requestBody: {
                content: {
                    "application/json": {
                        username: string;
                        password: string;
                    };
                };
            };
            responses: {
                /** @description logged in; sets the HttpOnly, SameSite=Strict session cookie (Secure under TLS) */
                200: {
                    headers: {
                        "Set-Cookie"?: string;
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Session"];
                    };
                };
                400: components["responses"]["BadRequest"];
                /** @description wrong username or password */
                401: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
                /** @description too many failed attempts for this user or address */
                429: {
                    headers: {
                        "Retry-After"?: number;
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
            };
        };
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/logout": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        get?: never;
        put?: never;
        /** Log out */
        post: {
            parameters: {
                query?: never;
                header?: never;
                path?: never;
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description the session ended; the cookie is cleared */
                204: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content?: never;
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
            };
        };
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/session": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** The caller's session and CSRF token */
        get: {
            parameters: {
                query?: never;
                header?: never;
                path?: never;
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description the session */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Session"];
                    };
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
            };
        };
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/accounts": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** Staff accounts */
        get: {
            parameters: {
                query?: never;
                header?: never;
                path?: never;
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description accounts */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": {
                            accounts?: components["schemas"]["Account"][];
                        };
                    };
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
            };
        };
        put?: never;
        /** Add a staff account */
        post: {
            parameters: {
                query?: never;
                header?: never;
                path?: never;
                cookie?: never;
            };
            requestBody: {
                content: {
                    "application/json": {
                        username: string;
                        password: string;
                        role: components["schemas"]["Role"];
                    };
                };
            };
            responses: {
                /** @description made */
                201: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Account"];
                    };
                };
                400: components["responses"]["BadRequest"];
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                409: components["responses"]["Conflict"];
            };
        };
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/accounts/{username}": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        get?: never;
        /** Change an account's role or password (a new password ends its sessions) */
        put: {
            parameters: {
                query?: never;
                header?: never;
                path: {
                    username: string;
                };
                cookie?: never;
            };
            requestBody: {
                content: {
                    "application/json": {
                        role?: components["schemas"]["Role"];
                        password?: string;
                    };
                };
            };
            responses: {
                /** @description changed */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Account"];
                    };
                };
                400: components["responses"]["BadRequest"];
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
                /** @description would leave no admin */
                409: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
            };
        };
        post?: never;
        /** Delete an account (never the last admin) */
        delete: {
            parameters: {
                query?: never;
                header?: never;
                path: {
                    username: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description deleted */
                204: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content?: never;
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
                /** @description the last admin */
                409: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
            };
        };
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/rig": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** Rig status: cameras, lasers, calibration (age, residuals), the job running */
        get: {
            parameters: {
                query?: never;
                header?: never;
                path?: never;
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description status */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["RigStatus"];
                    };
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
            };
        };
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/rig/calibrate": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        get?: never;
        put?: never;
        /** Calibrate the rig from the frames' lights, the dot grid and the lasers on the poles */
        post: {
            parameters: {
                query?: never;
                header?: never;
                path?: never;
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description started */
                202: {
                    headers: {
                        Location?: string;
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": {
                            job?: components["schemas"]["Job"];
                        };
                    };
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                /** @description the rig is busy with another job */
                409: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
            };
        };
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/rig/posture-check": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        get?: never;
        put?: never;
        /** Check how the customer stands: a quick coarse sweep (every 4th laser step) whose surface gives the arms, the feet and the turn, checked against the scanning posture; the result is the job's posture_check when it completes, and nothing is stored */
        post: {
            parameters: {
                query?: never;
                header?: never;
                path?: never;
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description started */
                202: {
                    headers: {
                        Location?: string;
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": {
                            job?: components["schemas"]["Job"];
                        };
                    };
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                /** @description the rig is busy with another job */
                409: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
            };
        };
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/scans": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** Find scans */
        get: {
            parameters: {
                query?: {
                    customer?: string;
                    /** @description words (at most 8), each found in any order and case in the scan id, the customer id, name or contact, or the operator */
                    q?: string;
                    /** @description ISO 8601 date prefix */
                    from?: string;
                    /** @description ISO 8601 date prefix */
                    to?: string;
                    /** @description 1-1000 (default 100) */
                    limit?: number;
                };
                header?: never;
                path?: never;
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description scans, newest first */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": {
                            scans?: components["schemas"]["Scan"][];
                        };
                    };
                };
                400: components["responses"]["BadRequest"];
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
            };
        };
        put?: never;
        /** Scan a customer (new or existing); calibrates first if the rig never was */
        post: {
            parameters: {
                query?: never;
                header?: never;
                path?: never;
                cookie?: never;
            };
            requestBody: {
                content: {
                    "application/json": {
                        customer_id?: string;
                        customer?: {
                            name?: string;
                            contact?: string;
                        };
                        /** @description scan every Nth laser step (default: the server's --every) */
                        every?: number;
                        /** @description the customer has just agreed to the terms of GET /api/consent: recorded with the time and the operator. Required for a new customer and for one with no consent on record */
                        consent?: boolean;
                    };
                };
            };
            responses: {
                /** @description started; the scan is in the archive as running */
                202: {
                    headers: {
                        Location?: string;
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": {
                            job?: components["schemas"]["Job"];
                        };
                    };
                };
                400: components["responses"]["BadRequest"];
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                /** @description no such customer */
                404: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
                /** @description the rig is busy with another job, or the customer's consent is not on record and not given */
                409: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
            };
        };
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/jobs/{id}": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** A job (the current or the last one) */
        get: {
            parameters: {
                query?: never;
                header?: never;
                path: {
                    id: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description the job */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": {
                            job?: components["schemas"]["Job"];
                        };
                    };
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
            };
        };
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/jobs/{id}/prompt": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        get?: never;
        put?: never;
        /** Answer the job's prompt: the person has done what it asked (held the dot-grid board before a camera, taken it out of the rig) */
        post: {
            parameters: {
                query?: never;
                header?: never;
                path: {
                    id: string;
                };
                cookie?: never;
            };
            requestBody: {
                content: {
                    "application/json": {
                        /** @description the id of the prompt answered (Job.prompt.id) */
                        prompt: string;
                    };
                };
            };
            responses: {
                /** @description answered; the job goes on */
                202: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": {
                            job?: components["schemas"]["Job"];
                        };
                    };
                };
                400: components["responses"]["BadRequest"];
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
                /** @description the job has ended, asks nothing, or asks a newer prompt */
                409: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
            };
        };
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/jobs/{id}/cancel": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        get?: never;
        put?: never;
        /** Cancel the running job (it stops at the next frame or stage; lasers off; the scan is marked cancelled) */
        post: {
            parameters: {
                query?: never;
                header?: never;
                path: {
                    id: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description cancelling */
                202: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": {
                            job?: components["schemas"]["Job"];
                        };
                    };
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
                /** @description the job has ended */
                409: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
            };
        };
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/consent": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** The terms a customer agrees to before their first scan: what is stored, for how long, who sees it */
        get: {
            parameters: {
                query?: never;
                header?: never;
                path?: never;
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description the terms */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": {
                            terms?: string;
                        };
                    };
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
            };
        };
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/customers": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** Find customers */
        get: {
            parameters: {
                query?: {
                    /** @description words (at most 8), each found in any order and case in the id, name or contact */
                    q?: string;
                };
                header?: never;
                path?: never;
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description customers */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": {
                            customers?: components["schemas"]["Customer"][];
                        };
                    };
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
            };
        };
        put?: never;
        /** Add a customer */
        post: {
            parameters: {
                query?: never;
                header?: never;
                path?: never;
                cookie?: never;
            };
            requestBody: {
                content: {
                    "application/json": {
                        name?: string;
                        contact?: string;
                    };
                };
            };
            responses: {
                /** @description made */
                201: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Customer"];
                    };
                };
                400: components["responses"]["BadRequest"];
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
            };
        };
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/customers/{id}": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** A customer and their scans */
        get: {
            parameters: {
                query?: never;
                header?: never;
                path: {
                    id: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description the customer */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Customer"];
                    };
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
            };
        };
        put?: never;
        post?: never;
        /** Erase a customer: records, scans, files, share links, audit entries naming them */
        delete: {
            parameters: {
                query?: never;
                header?: never;
                path: {
                    id: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description erased */
                204: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content?: never;
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
            };
        };
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/scans/{id}": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** A scan: status, versions, files */
        get: {
            parameters: {
                query?: never;
                header?: never;
                path: {
                    id: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description the scan */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Scan"];
                    };
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
            };
        };
        put?: never;
        post?: never;
        /** Delete a scan and its share links */
        delete: {
            parameters: {
                query?: never;
                header?: never;
                path: {
                    id: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description deleted */
                204: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content?: never;
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
                /** @description the scan is being processed */
                409: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
            };
        };
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/scans/{id}/reprocess": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        get?: never;
        put?: never;
        /** Process the scan again from its raw record into a new version */
        post: {
            parameters: {
                query?: never;
                header?: never;
                path: {
                    id: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description started */
                202: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": {
                            job?: components["schemas"]["Job"];
                        };
                    };
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
                /** @description busy, or no raw record */
                409: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
            };
        };
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/scans/{id}/mesh.glb": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** The surface: glTF binary with KHR_draco_mesh_compression, metres */
        get: {
            parameters: {
                query?: {
                    /** @description a version number (default: the current one) */
                    version?: number;
                };
                header?: never;
                path: {
                    id: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description the model */
                200: {
                    headers: {
                        /** @description the file's BLAKE2b (first 128 bits) */
                        ETag?: string;
                        /** @description private, no-cache for the current version; immutable for ?version=N */
                        "Cache-Control"?: string;
                        [name: string]: unknown;
                    };
                    content: {
                        "model/gltf-binary": string;
                    };
                };
                /** @description not modified (If-None-Match) */
                304: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content?: never;
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
            };
        };
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/scans/{id}/points.drc": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** The point cloud: Draco, metres */
        get: {
            parameters: {
                query?: {
                    /** @description a version number (default: the current one) */
                    version?: number;
                };
                header?: never;
                path: {
                    id: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description the cloud */
                200: {
                    headers: {
                        /** @description the file's BLAKE2b (first 128 bits) */
                        ETag?: string;
                        /** @description private, no-cache for the current version; immutable for ?version=N */
                        "Cache-Control"?: string;
                        [name: string]: unknown;
                    };
                    content: {
                        "application/octet-stream": string;
                    };
                };
                /** @description not modified (If-None-Match) */
                304: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content?: never;
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
            };
        };
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/scans/{id}/measurements": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** The automatic set (ISO 8559-1) and the measurements staff saved, with the geometry to draw */
        get: {
            parameters: {
                query?: never;
                header?: never;
                path: {
                    id: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description measurements (gzip with Accept-Encoding: gzip; ETag) */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": {
                            scan_id?: string;
                            version?: number;
                            measurements?: components["schemas"]["StoredMeasurement"][];
                            posture?: components["schemas"]["Posture"];
                        };
                    };
                };
                /** @description not modified (If-None-Match) */
                304: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content?: never;
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
            };
        };
        put?: never;
        /** Evaluate and save a named measurement */
        post: {
            parameters: {
                query?: never;
                header?: never;
                path: {
                    id: string;
                };
                cookie?: never;
            };
            requestBody: {
                content: {
                    "application/json": {
                        name: string;
                        label?: string;
                        request: components["schemas"]["MeasureRequest"];
                    };
                };
            };
            responses: {
                /** @description saved */
                201: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["StoredMeasurement"];
                    };
                };
                400: components["responses"]["BadRequest"];
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
                /** @description the scan has no surface */
                409: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
                /** @description nothing to measure there */
                422: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
            };
        };
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/scans/{id}/repeat": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** The scan against its customer's earlier scan the same day (the workstation's local day): the automatic values that differ by more than the shop's repeatability (bodyscan serve --repeatability), else each value's ISO 20685-1 allowance */
        get: {
            parameters: {
                query?: never;
                header?: never;
                path: {
                    id: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description the comparison; earlier is null when there is no earlier scan that day */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": {
                            earlier?: {
                                id?: string;
                                started_at?: string;
                            } | null;
                            /** @description the shop's; null: each value's ISO 20685-1 allowance */
                            repeatability_mm?: number | null;
                            /** @description automatic values both scans have */
                            compared?: number;
                            beyond?: {
                                name?: string;
                                label?: string;
                                kind?: string;
                                value_mm?: number;
                                earlier_mm?: number;
                                /** @description this scan's minus the earlier's */
                                difference_mm?: number;
                                tolerance_mm?: number;
                            }[];
                        };
                    };
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
            };
        };
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/scans/{id}/measure": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        get?: never;
        put?: never;
        /** Evaluate a girth, arc, surface length or distance the browser drew (mm, scan frame) */
        post: {
            parameters: {
                query?: never;
                header?: never;
                path: {
                    id: string;
                };
                cookie?: never;
            };
            requestBody: {
                content: {
                    "application/json": components["schemas"]["MeasureRequest"];
                };
            };
            responses: {
                /** @description the value and its geometry */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Measurement"];
                    };
                };
                400: components["responses"]["BadRequest"];
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
                /** @description the scan has no surface */
                409: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
                /** @description nothing to measure there */
                422: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
            };
        };
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/scans/{id}/measurements/{mid}": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        get?: never;
        put?: never;
        post?: never;
        /** Delete a saved measurement (the automatic set stays) */
        delete: {
            parameters: {
                query?: never;
                header?: never;
                path: {
                    id: string;
                    mid: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description deleted */
                204: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content?: never;
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
            };
        };
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/scans/{id}/avatar.obj": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** Avatar for CAD tools, Wavefront OBJ: the surface decimated to a triangle budget, closed */
        get: {
            parameters: {
                query?: {
                    /** @description the triangle budget, 1000 to 5000000 (default 70000, CLO3D's recommendation) */
                    triangles?: number;
                    /** @description mm (default) or m; OBJ has no unit, the importer is told */
                    unit?: string;
                };
                header?: never;
                path: {
                    id: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description the avatar (Content-Disposition: attachment). X-Avatar-Triangles: its triangles; X-Avatar-Closed: true when every edge joins two triangles; X-Avatar-Deviation-Mm: the largest distance between its vertices and the full surface, both ways */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "model/obj": string;
                    };
                };
                400: components["responses"]["BadRequest"];
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
            };
        };
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/scans/{id}/avatar.glb": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** Avatar for CAD tools, glTF binary with plain accessors (no Draco), metres: the surface decimated to a triangle budget, closed */
        get: {
            parameters: {
                query?: {
                    /** @description the triangle budget, 1000 to 5000000 (default 70000, CLO3D's recommendation) */
                    triangles?: number;
                    /** @description m (default and only: glTF is metres) */
                    unit?: string;
                };
                header?: never;
                path: {
                    id: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description the avatar (Content-Disposition: attachment), with the headers of avatar.obj */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "model/gltf-binary": string;
                    };
                };
                400: components["responses"]["BadRequest"];
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
            };
        };
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/scans/{id}/sheet.csv": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** Measurement sheet, RFC 4180 CSV */
        get: {
            parameters: {
                query?: {
                    /** @description mm, cm or in (default: the profile's: mm, or cm for mtm-order) */
                    unit?: string;
                    /** @description the CSV's layout (docs/archive.md, "Export profiles"): sheet (default: a row per measurement), iso8559 (a row per measurement with an ISO 8559-1 clause, keyed by clause and side), mtm-order (one row under a made-to-measure order's column names, in cm unless 'unit' says otherwise) */
                    profile?: "sheet" | "iso8559" | "mtm-order";
                };
                header?: never;
                path: {
                    id: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description the sheet (Content-Disposition: attachment) */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "text/csv": string;
                    };
                };
                400: components["responses"]["BadRequest"];
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
            };
        };
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/scans/{id}/sheet.json": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** Measurement sheet, bodyscan.sheet/1 */
        get: {
            parameters: {
                query?: {
                    /** @description mm (default), cm or in */
                    unit?: string;
                };
                header?: never;
                path: {
                    id: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description the sheet (Content-Disposition: attachment) */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": string;
                    };
                };
                400: components["responses"]["BadRequest"];
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
            };
        };
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/scans/{id}/sheet.pdf": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** Measurement sheet, one A4 page with silhouettes and lines */
        get: {
            parameters: {
                query?: {
                    /** @description mm (default), cm or in */
                    unit?: string;
                };
                header?: never;
                path: {
                    id: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description the sheet (Content-Disposition: attachment) */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/pdf": string;
                    };
                };
                400: components["responses"]["BadRequest"];
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
            };
        };
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/scans/{id}/shares": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** A scan's share links (tokens are never shown again) */
        get: {
            parameters: {
                query?: never;
                header?: never;
                path: {
                    id: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description links */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": {
                            shares?: components["schemas"]["Share"][];
                        };
                    };
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
            };
        };
        put?: never;
        /** Make a customer share link (read-only, expiring, revocable) */
        post: {
            parameters: {
                query?: never;
                header?: never;
                path: {
                    id: string;
                };
                cookie?: never;
            };
            requestBody: {
                content: {
                    "application/json": {
                        /** @default 7 */
                        days?: number;
                        /** @description names of the measurements the customer sees */
                        measurements?: string[];
                        /**
                         * @description show the head in the model the link serves; by default the model is cut below the neck girth's lowest point
                         * @default false
                         */
                        include_head?: boolean;
                        /**
                         * @description protect the link with a six-digit PIN that staff read out; the answer's pin_code holds it, once. The link then opens only with X-Share-PIN; five wrong PINs withdraw it
                         * @default false
                         */
                        pin?: boolean;
                    };
                };
            };
            responses: {
                /** @description the link; the token is shown only now */
                201: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["NewShare"];
                    };
                };
                400: components["responses"]["BadRequest"];
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
                /** @description the scan has no results */
                409: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
            };
        };
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/shares/{id}": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        get?: never;
        put?: never;
        post?: never;
        /** Withdraw a share link */
        delete: {
            parameters: {
                query?: never;
                header?: never;
                path: {
                    id: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description withdrawn */
                204: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content?: never;
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
            };
        };
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/share/{token}": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** The customer's view: when the scan was taken and the measurements shared */
        get: {
            parameters: {
                query?: {
                    /** @description the language of the plain labels: en or de; default: the shop's */
                    locale?: "en" | "de";
                };
                header?: {
                    /** @description the link's PIN, for a link made with one */
                    "X-Share-PIN"?: string;
                };
                path: {
                    /** @description the link's 128-bit token */
                    token: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description the shared scan */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": {
                            taken_at?: string;
                            expires_at?: number;
                            mesh?: string;
                            measurements?: (components["schemas"]["StoredMeasurement"] & {
                                /** @description the measurement's plain name in the shop's language (absent for one staff took) */
                                plain_label?: string;
                            })[];
                            /**
                             * @description the language of the plain labels: the one asked for, else the shop's (bodyscan serve --locale)
                             * @enum {string}
                             */
                            locale?: "en" | "de";
                            /** @description the shop's name; empty when not configured */
                            shop?: string;
                        };
                    };
                };
                /** @description an unknown locale */
                400: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
                /** @description the link has a PIN and X-Share-PIN is missing or wrong (the message says how many tries are left) */
                401: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
                /** @description unknown, expired or withdrawn link (one answer for all) */
                404: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
            };
        };
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/share/{token}/mesh.glb": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** The customer's model: without the head (cut below the neck girth) unless the link includes it */
        get: {
            parameters: {
                query?: never;
                header?: {
                    /** @description the link's PIN, for a link made with one */
                    "X-Share-PIN"?: string;
                };
                path: {
                    /** @description the link's 128-bit token */
                    token: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description the model */
                200: {
                    headers: {
                        /** @description the file's BLAKE2b (first 128 bits) */
                        ETag?: string;
                        /** @description private, no-cache for the current version; immutable for ?version=N */
                        "Cache-Control"?: string;
                        [name: string]: unknown;
                    };
                    content: {
                        "model/gltf-binary": string;
                    };
                };
                /** @description not modified */
                304: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content?: never;
                };
                /** @description the link has a PIN and X-Share-PIN is missing or wrong (the message says how many tries are left) */
                401: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
                /** @description unknown, expired or withdrawn link */
                404: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
            };
        };
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/share/{token}/sheet.pdf": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** The customer's sheet: one A4 page with their name, the shared measurements under plain names, the silhouette, the shop and the link as a QR code, in the shop's language */
        get: {
            parameters: {
                query?: {
                    /** @description mm, cm (default) or in */
                    unit?: "mm" | "cm" | "in";
                    /** @description en or de; default: the shop's language */
                    locale?: "en" | "de";
                };
                header?: {
                    /** @description the link's PIN, for a link made with one */
                    "X-Share-PIN"?: string;
                };
                path: {
                    /** @description the link's 128-bit token */
                    token: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description the sheet */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/pdf": string;
                    };
                };
                /** @description an unknown unit or locale */
                400: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
                /** @description the link has a PIN and X-Share-PIN is missing or wrong (the message says how many tries are left) */
                401: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
                /** @description unknown, expired or withdrawn link */
                404: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": components["schemas"]["Error"];
                    };
                };
            };
        };
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/events": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /**
         * WebSocket: job progress, camera previews, rig status, scan finished
         * @description Upgrade with a staff session cookie. Each client has its own bounded queue: when it falls behind, camera previews are skipped, and a client too far behind is disconnected.
         */
        get: {
            parameters: {
                query?: never;
                header?: never;
                path?: never;
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description switching to the WebSocket protocol; messages are JSON text: hello {rig}, job {job}, preview {job, camera, frame_id, png_base64}, rig {rig}, scan_finished {job} */
                101: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content?: never;
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
            };
        };
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/scans/{id}/tape": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** The tape measurements staff entered for the scan */
        get: {
            parameters: {
                query?: never;
                header?: never;
                path: {
                    id: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description the scan's tape values */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": {
                            scan_id: string;
                            tape: components["schemas"]["TapeMeasurement"][];
                        };
                    };
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
            };
        };
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/scans/{id}/tape/{name}": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        get?: never;
        /** Enter (or replace) the tape value of one of the scan's automatic measurements */
        put: {
            parameters: {
                query?: never;
                header?: never;
                path: {
                    id: string;
                    /** @description an automatic measurement's name */
                    name: string;
                };
                cookie?: never;
            };
            requestBody: {
                content: {
                    "application/json": {
                        /** @description the tape's reading, 1 to 3000 mm */
                        value_mm: number;
                        /** @description who took it (up to 200 characters); default the caller */
                        measured_by?: string;
                    };
                };
            };
            responses: {
                /** @description the scan's tape values */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": {
                            scan_id: string;
                            tape: components["schemas"]["TapeMeasurement"][];
                        };
                    };
                };
                400: components["responses"]["BadRequest"];
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
                409: components["responses"]["Conflict"];
            };
        };
        post?: never;
        /** Remove the tape value of one measurement */
        delete: {
            parameters: {
                query?: never;
                header?: never;
                path: {
                    id: string;
                    name: string;
                };
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description removed */
                204: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content?: never;
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
                404: components["responses"]["NotFound"];
            };
        };
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/validation": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** ISO 20685-1 validation: per measurement, the mean scan-minus-tape difference over the customers with tape values, its 95 % confidence interval and whether it lies within the standard's allowance */
        get: {
            parameters: {
                query?: never;
                header?: never;
                path?: never;
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description the report */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/json": {
                            customers: number;
                            tape_values: number;
                            confidence: number;
                            measurements: {
                                name: string;
                                label: string;
                                kind: string;
                                iso_clause: string;
                                /** @description ISO 20685-1's: 9 large girths; 4 small girths, heights, breadths; 5 lengths, depths */
                                allowance_mm: number;
                                /** @description customers compared, each once (their newest scan with a tape value) */
                                subjects: number;
                                /** @description mean of scan minus tape */
                                mean_difference_mm: number;
                                sd_mm: number | null;
                                /** @description 95 % confidence interval of the mean (Student t); null below two customers */
                                ci_low_mm: number | null;
                                ci_high_mm: number | null;
                                /** @enum {string} */
                                verdict: "within" | "more_subjects" | "outside" | "too_few";
                                /** @description more_subjects: customers still needed for the interval to fit if mean and spread hold; too_few: still needed for a first interval */
                                more_subjects: number;
                                measured_by: string[];
                            }[];
                        };
                    };
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
            };
        };
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/validation.pdf": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** The validation report as A4 pages for the shop's files */
        get: {
            parameters: {
                query?: never;
                header?: never;
                path?: never;
                cookie?: never;
            };
            requestBody?: never;
            responses: {
                /** @description the report (Content-Disposition: attachment) */
                200: {
                    headers: {
                        [name: string]: unknown;
                    };
                    content: {
                        "application/pdf": string;
                    };
                };
                401: components["responses"]["Unauthorized"];
                403: components["responses"]["Forbidden"];
            };
        };
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
}
export type webhooks = Record<string, never>;
export interface components {
    schemas: {
        Error: {
            error?: {
                status?: number;
                code?: string;
                message?: string;
                /** @description a share link's wrong PIN: the tries left before it is withdrawn */
                tries_left?: number;
            };
        };
        /** @enum {string} */
        Role: "operator" | "tailor" | "admin";
        Session: {
            username?: string;
            role?: components["schemas"]["Role"];
            /** @description send as X-CSRF-Token on every state-changing request */
            csrf_token?: string;
            expires_at?: number;
        };
        Account: {
            username?: string;
            role?: components["schemas"]["Role"];
            created_at?: string;
        };
        Job: {
            id?: string;
            /** @enum {string} */
            kind?: "calibrate" | "scan" | "reprocess" | "posture_check";
            /** @enum {string} */
            state?: "running" | "complete" | "failed" | "cancelled";
            stage?: string;
            fraction?: number;
            frames?: number;
            scan_id?: string;
            customer_id?: string;
            actor?: string;
            error?: string;
            started_at?: string;
            finished_at?: string;
            version?: number;
            /** @description what the job waits for a person to do; null when nothing */
            prompt?: components["schemas"]["JobPrompt"] | null;
            /** @description a posture check's result, once it completes */
            posture_check?: {
                posture?: components["schemas"]["Posture"];
                /** @description the arms, the feet and the turn inside the scanning posture (the head is left to the scan) */
                ok?: boolean;
                /** @description camera frames the sweep took, all cameras */
                frames?: number;
                points?: number;
                acquisition_seconds?: number;
                /** @description cloud, surface and posture after the last frame */
                processing_seconds?: number;
            };
        };
        RigStatus: {
            rig?: string;
            simulated?: boolean;
            busy?: boolean;
            cameras?: Record<string, unknown>[];
            lasers?: {
                id?: string;
                /** @description null while a job owns the lasers */
                on?: boolean | null;
            }[];
            calibration?: {
                id?: string;
                calibrated_at?: number;
                age_s?: number;
                cameras?: Record<string, unknown>[];
            } | null;
            job?: components["schemas"]["Job"] | null;
        };
        Customer: {
            id?: string;
            name?: string | null;
            contact?: string | null;
            created_at?: string;
            /** @description the latest consent recorded; null: no scan may start until one is */
            consent?: components["schemas"]["Consent"] | null;
            scans?: components["schemas"]["Scan"][];
        };
        Scan: {
            id?: string;
            customer_id?: string;
            operator?: string;
            calibration_id?: string;
            /** @enum {string} */
            status?: "running" | "complete" | "failed" | "cancelled";
            status_reason?: string;
            started_at?: string;
            finished_at?: string;
            current_version?: number;
            versions?: Record<string, unknown>[];
        };
        MeasureRequest: {
            /** @enum {string} */
            kind: "girth" | "arc" | "surface" | "distance";
            plane?: {
                /** @description [x, y, z] mm, scan frame (Y up) */
                point?: number[];
                /** @description [x, y, z] mm, scan frame (Y up) */
                normal?: number[];
            };
            /** @description a line drawn on screen, with 'view' */
            line?: {
                /** @description [x, y, z] mm, scan frame (Y up) */
                from?: number[];
                /** @description [x, y, z] mm, scan frame (Y up) */
                to?: number[];
            };
            /** @description [x, y, z] mm, scan frame (Y up) */
            view?: number[];
            /** @description [x, y, z] mm, scan frame (Y up) */
            near?: number[];
            /** @description [x, y, z] mm, scan frame (Y up) */
            from?: number[];
            /** @description [x, y, z] mm, scan frame (Y up) */
            to?: number[];
        };
        Measurement: {
            kind?: string;
            value_mm?: number;
            path?: number[][];
            closed?: boolean;
            crosses_filled_hole?: boolean;
            /** @description how far skin the cameras did not see (filled in) could move the value, mm: along the line, each filled stretch's length beyond the straight chord between the seen skin either side; at a landmark on filled skin, its offset from the nearest seen skin in the direction the value is read (docs/measurements.md); null where not known */
            fill_bound_mm?: number | null;
            /** @description an estimate: the line crosses filled-in skin that could move it by more than 2 mm (or by an amount not known) */
            estimated?: boolean;
            algorithm?: string;
            /** @description what the definition assumes of the posture (automatic set; absent when nothing) */
            posture_assumed?: string;
            /** @description the customer stood outside that posture: the value is not the standard's */
            outside_posture?: boolean;
        } & {
            [key: string]: unknown;
        };
        StoredMeasurement: {
            id?: number;
            version?: number;
            /** @enum {string} */
            source?: "automatic" | "user";
            name?: string;
            label?: string;
            kind?: string;
            iso_clause?: string;
            value_mm?: number;
            geometry?: components["schemas"]["Measurement"];
            created_by?: string;
            created_at?: string;
        };
        Share: {
            id?: string;
            scan_id?: string;
            measurements?: string[];
            created_by?: string;
            created_at?: string;
            expires_at?: number;
            revoked?: boolean;
            include_head?: boolean;
            /** @description the link asks for a PIN */
            pin?: boolean;
        };
        NewShare: components["schemas"]["Share"] & {
            token?: string;
            url?: string;
            /** @description the link's six-digit PIN, when made with pin: shown only in this answer */
            pin_code?: string;
        };
        /** @description what the job waits for a person to do */
        JobPrompt: {
            /** @description answer with POST /api/jobs/{id}/prompt {"prompt": id} */
            id: string;
            /** @enum {string} */
            kind: "hold_dot_grid" | "remove_dot_grid";
            /** @description the camera to hold the board before (hold_dot_grid) */
            camera?: string;
            /** @description the instruction, for the station to show */
            text: string;
            /** @description why the last picture of the board could not be used */
            why?: string;
            asked_at: string;
        };
        /** @description How the customer stood, read from the surface, and each part checked against the scanning posture the measurement rules assume (docs/measurements.md, Posture); null for scans measured before it was recorded */
        Posture: {
            /** @description the facing from the rig's front (+Z) toward +X */
            turn_deg?: number;
            /** @description X, Z of the trunk's centre on the floor */
            position_mm?: number[];
            /** @description left, right: the upper arm from the downward vertical */
            arm_abduction_deg?: (number | null)[];
            /** @description left, right; 0 straight */
            elbow_bend_deg?: (number | null)[];
            ankle_distance_mm?: number | null;
            /** @description forward + */
            head_tilt_deg?: number | null;
            /** @description toward the body's left + */
            head_side_tilt_deg?: number | null;
            /** @description every part inside the scanning posture */
            ok?: boolean;
            checks?: {
                /** @enum {string} */
                part?: "arm_left" | "arm_right" | "feet" | "head" | "turn";
                ok?: boolean;
                /** @description what to ask of the customer when not ok */
                message?: string;
            }[];
        } | null;
        /** @description the terms the customer agreed to, word for word, when, and who recorded it */
        Consent: {
            given_at?: string;
            recorded_by?: string;
            terms?: string;
        };
        /** @description A value staff measured on the customer by hand for one of the scan's automatic measurements (ISO 20685-1 validation) */
        TapeMeasurement: {
            scan_id: string;
            /** @description the automatic measurement's name, e.g. waist_girth */
            name: string;
            value_mm: number;
            /** @description who took it */
            measured_by: string;
            entered_by: string;
            /** Format: date-time */
            entered_at: string;
        };
    };
    responses: {
        /** @description malformed request */
        BadRequest: {
            headers: {
                [name: string]: unknown;
            };
            content: {
                "application/json": components["schemas"]["Error"];
            };
        };
        /** @description no valid session (log in) */
        Unauthorized: {
            headers: {
                [name: string]: unknown;
            };
            content: {
                "application/json": components["schemas"]["Error"];
            };
        };
        /** @description the role may not do this, or the CSRF token is missing or wrong, or a cross-site request */
        Forbidden: {
            headers: {
                [name: string]: unknown;
            };
            content: {
                "application/json": components["schemas"]["Error"];
            };
        };
        /** @description no such record */
        NotFound: {
            headers: {
                [name: string]: unknown;
            };
            content: {
                "application/json": components["schemas"]["Error"];
            };
        };
        /** @description conflicts with the current state */
        Conflict: {
            headers: {
                [name: string]: unknown;
            };
            content: {
                "application/json": components["schemas"]["Error"];
            };
        };
    };
    parameters: never;
    requestBodies: never;
    headers: never;
    pathItems: never;
}
export type $defs = Record<string, never>;
export type operations = Record<string, never>;
