"""Abaqus/Explicit user subroutine VFRIC (contact pairs) in fixed-form Fortran 77, and the inverse relation
(1.8) it needs: the limit force whose slip direction is given, solved by Newton's method on
the law's printed local functions.
"""

INVERSE = """\
C ----------------------------------------------------------------------
C The inverse relation at N = 1: the force T on the limit surface whose
C tangential slip direction is (C, S) (a unit vector). IOK = 0 where
C Newton fails.
      SUBROUTINE @P@IR(C, S, Q, P, T, IOK)
      IMPLICIT NONE
@PARAMS@
      DOUBLE PRECISION C, S, Q(NQS), P(*), T(2), W(NSIZE), WK(NSIZE)
      DOUBLE PRECISION R, PHI, DPHI, R1, R2, A11, A12, A21, A22, DET
      DOUBLE PRECISION D1, D2, TK1, TK2, AMER, AMK, ALPHA, SC
      INTEGER IOK, IT, IH, K
      LOGICAL ACCEPT
      IOK = 0
      DO 5 K = 1, NSIZE
         W(K) = 0.0D0
         WK(K) = 0.0D0
    5 CONTINUE
      R = 1.0D0
      DO 10 IT = 1, @SCALAR_MAX_ITER@
         CALL @P@EV(R*C, R*S, 1.0D0, Q, P, W, 1)
         PHI = W(1)
         DPHI = W(OFFDF + 1)*C + W(OFFDF + 2)*S
         IF (ABS(PHI) .LE. @SCALAR_TOL@*(1.0D0 + R)) GO TO 20
         IF (.NOT. (DPHI .GT. 0.0D0)) RETURN
         IF (R - PHI/DPHI .LE. 0.0D0) THEN
            R = 0.5D0*R
         ELSE
            R = R - PHI/DPHI
         END IF
   10 CONTINUE
      RETURN
   20 T(1) = R*C
      T(2) = R*S
C     f = 0 and grad_T g parallel to (C, S): Newton with line search.
      SC = 1.0D0/MAX(SQRT(W(OFFDF + 1)**2 + W(OFFDF + 2)**2), 1.0D-300)
      CALL @P@EV(T(1), T(2), 1.0D0, Q, P, W, 2)
      R1 = W(1)*SC
      R2 = W(OFFDG + 1)*S - W(OFFDG + 2)*C
      AMER = SQRT(R1*R1 + R2*R2)
      DO 50 IT = 1, @MAX_ITER@
         IF (AMER .LE. @TOL@) GO TO 60
         A11 = W(OFFDF + 1)*SC
         A12 = W(OFFDF + 2)*SC
         A21 = W(OFFHGG + 1)*S - W(OFFHGG + 4)*C
         A22 = W(OFFHGG + 2)*S - W(OFFHGG + 5)*C
         DET = A11*A22 - A12*A21
         IF (.NOT. (ABS(DET) .GT. 1.0D-300)) RETURN
         D1 = -(A22*R1 - A12*R2)/DET
         D2 = -(A11*R2 - A21*R1)/DET
         ALPHA = 1.0D0
         ACCEPT = .FALSE.
         DO 40 IH = 1, @MAX_HALVINGS@
            TK1 = T(1) + ALPHA*D1
            TK2 = T(2) + ALPHA*D2
            CALL @P@EV(TK1, TK2, 1.0D0, Q, P, WK, 2)
            R1 = WK(1)*SC
            R2 = WK(OFFDG + 1)*S - WK(OFFDG + 2)*C
            AMK = SQRT(R1*R1 + R2*R2)
            IF (AMK .LE. (1.0D0 - @SUFFICIENT_DECREASE@*ALPHA)*AMER) THEN
               T(1) = TK1
               T(2) = TK2
               AMER = AMK
               DO 30 K = 1, NSIZE
                  W(K) = WK(K)
   30          CONTINUE
               ACCEPT = .TRUE.
               GO TO 45
            END IF
            ALPHA = 0.5D0*ALPHA
   40    CONTINUE
   45    IF (.NOT. ACCEPT) RETURN
   50 CONTINUE
      RETURN
   60 IF (W(OFFDG + 1)*C + W(OFFDG + 2)*S .GT. 0.0D0) IOK = 1
      RETURN
      END
C ----------------------------------------------------------------------
C Internal variables after a slip DLAM, as changes from the virgin Q0:
C QOUT = Q + DLAM H - Q0 (H in W).
      SUBROUTINE @P@UQ(Q, Q0, W, DLAM, QOUT)
      IMPLICIT NONE
@PARAMS@
      DOUBLE PRECISION Q(NQS), Q0(NQS), W(*), DLAM, QOUT(*)
      INTEGER J, NQV
      NQV = NQ
      DO 10 J = 1, NQV
         QOUT(J) = Q(J) + DLAM*W(OFFH + J) - Q0(J)
   10 CONTINUE
      RETURN
      END
"""

VFRIC = """\
      SUBROUTINE VFRIC(
C Write only -
     *     fTangential,
C Read/Write -
     *     statev,
C Read only -
     *     kStep, kInc, nContact, nFacNod, nSlvNod, nMstNod,
     *     nFricDir, nDir, nStateVar, nProps, nTemp, nPred, numDefTfv,
     *     jSlvUid, jMstUid, jConSlvid, jConMstid, timStep, timGlb,
     *     dTimPrev, surfInt, surfSlv, surfMast, lContType,
     *     dSlipFric, fStickForce, fTangPrev, fNormal, frictionWork,
     *     shape, coordSlv, coordMst, dircosSl, dircosN, props,
     *     areaSlv, tempSlv, preDefSlv, tempMst, preDefMst)
C
      INCLUDE 'vaba_param.inc'
C
      DIMENSION props(nProps), statev(nStateVar, nSlvNod),
     1     dSlipFric(nDir, nContact),
     2     fTangential(nFricDir, nContact),
     3     fTangPrev(nDir, nContact),
     4     fStickForce(nContact), areaSlv(nSlvNod),
     5     fNormal(nContact), shape(nFacNod, nContact),
     6     coordSlv(nDir, nSlvNod), coordMst(nDir, nMstNod),
     7     dircosSl(nDir, nContact), dircosN(nDir, nContact),
     8     jSlvUid(nSlvNod), jMstUid(nMstNod),
     9     jConSlvid(nContact), jConMstid(nFacNod, nContact),
     1     tempSlv(nContact), tempMst(numDefTfv),
     2     preDefSlv(nContact, nPred),
     3     preDefMst(numDefTfv, nPred)
      CHARACTER*8 surfInt, surfSlv, surfMast
C
@PARAMS@
      INTEGER NPAR
      PARAMETER (NPAR = @NPAR@)
      DOUBLE PRECISION Q0(NQS)
      DOUBLE PRECISION P(NPAR + 1), Q(NQS), W(NSIZE), T(2), AN(3)
      DOUBLE PRECISION SL(3), REF(3), B1(3), B2(3), AM1(3), AM2(3)
      DOUBLE PRECISION G(3), S2(3), PHI, CS, SN, FN, F1, F2, FMAG
      DOUBLE PRECISION SCALE, DOT, ALEN, GT, DLAM, DS
      INTEGER KB, I, J, IOK, NQV, NODE
      DATA Q0 /@Q0@/
      NQV = NQ
      IF (.FALSE.) WRITE (*, *) kStep, kInc, nTemp, jSlvUid(1),
     &     jMstUid(1), jConMstid(1, 1), timStep, timGlb, dTimPrev,
     &     surfInt, surfSlv, surfMast, lContType, fTangPrev(1, 1),
     &     frictionWork, shape(1, 1), coordSlv(1, 1), coordMst(1, 1),
     &     areaSlv(1), tempSlv(1), tempMst(1), preDefSlv(1, 1),
     &     preDefMst(1, 1)
      IF (nProps .LT. NPAR + 1 .OR. nStateVar .LT. NQ) THEN
         WRITE (*, *) 'VFRIC (frictionrules): needs PROPERTIES = ',
     &        NPAR + 1, ' and DEPVAR = ', NQ
         CALL XPLB_EXIT
      END IF
      DO 10 I = 1, NPAR + 1
         P(I) = props(I)
   10 CONTINUE
      PHI = props(NPAR + 1)
      DO 15 I = 1, NSIZE
         W(I) = 0.0D0
   15 CONTINUE
      DO 200 KB = 1, nContact
         NODE = jConSlvid(KB)
         DO 20 I = 1, nFricDir
            fTangential(I, KB) = 0.0D0
   20    CONTINUE
         FN = fNormal(KB)
         IF (.NOT. (FN .GT. 0.0D0)) GO TO 200
         DO 30 J = 1, NQV
            Q(J) = statev(J, NODE) + Q0(J)
   30    CONTINUE
         AN(3) = 0.0D0
         SL(3) = 0.0D0
         DO 40 I = 1, nDir
            AN(I) = dircosN(I, KB)
            SL(I) = dircosSl(I, KB)
   40    CONTINUE
C        Material frame: global 1 (or 2 where the normal is closer to
C        it) projected on the tangent plane, in 2-D the in-plane tangent
C        (N2, -N1, 0); B2 = N x B1 (out of the plane in 2-D); both
C        turned by PHI about N. In 2-D there is no motion out of the
C        plane: the slip lies along B1 and the out-of-plane force is a
C        reaction (not returned with nFricDir = 1).
         IF (nDir .EQ. 3) THEN
            REF(1) = 1.0D0
            REF(2) = 0.0D0
            REF(3) = 0.0D0
            IF (ABS(AN(1)) .GT. SQRT(0.5D0)) THEN
               REF(1) = 0.0D0
               REF(2) = 1.0D0
            END IF
            DOT = REF(1)*AN(1) + REF(2)*AN(2) + REF(3)*AN(3)
            DO 50 I = 1, 3
               B1(I) = REF(I) - DOT*AN(I)
   50       CONTINUE
            ALEN = SQRT(B1(1)**2 + B1(2)**2 + B1(3)**2)
            DO 60 I = 1, 3
               B1(I) = B1(I)/ALEN
   60       CONTINUE
         ELSE
            B1(1) = AN(2)
            B1(2) = -AN(1)
            B1(3) = 0.0D0
         END IF
         B2(1) = AN(2)*B1(3) - AN(3)*B1(2)
         B2(2) = AN(3)*B1(1) - AN(1)*B1(3)
         B2(3) = AN(1)*B1(2) - AN(2)*B1(1)
         DO 70 I = 1, 3
            AM1(I) = COS(PHI)*B1(I) + SIN(PHI)*B2(I)
            AM2(I) = -SIN(PHI)*B1(I) + COS(PHI)*B2(I)
   70    CONTINUE
         CS = SL(1)*AM1(1) + SL(2)*AM1(2) + SL(3)*AM1(3)
         SN = SL(1)*AM2(1) + SL(2)*AM2(2) + SL(3)*AM2(3)
         ALEN = SQRT(CS*CS + SN*SN)
         IF (.NOT. (ALEN .GT. 0.0D0)) GO TO 200
         CS = CS/ALEN
         SN = SN/ALEN
         CALL @P@IR(CS, SN, Q, P, T, IOK)
         IF (IOK .EQ. 0) THEN
C           No force slides that way (or no convergence): stick.
            fTangential(1, KB) = -fStickForce(KB)
            GO TO 200
         END IF
C        The force for the slip direction, scaled by the normal force,
C        in the slip frame (1 along the slip, 2 = N x slip).
         DO 80 I = 1, 3
            G(I) = FN*(T(1)*AM1(I) + T(2)*AM2(I))
   80    CONTINUE
         S2(1) = AN(2)*SL(3) - AN(3)*SL(2)
         S2(2) = AN(3)*SL(1) - AN(1)*SL(3)
         S2(3) = AN(1)*SL(2) - AN(2)*SL(1)
         F1 = G(1)*SL(1) + G(2)*SL(2) + G(3)*SL(3)
         F2 = G(1)*S2(1) + G(2)*S2(2) + G(3)*S2(3)
         IF (nFricDir .EQ. 1) F2 = 0.0D0
         FMAG = SQRT(F1*F1 + F2*F2)
         SCALE = 1.0D0
         IF (FMAG .GT. fStickForce(KB)) THEN
            SCALE = fStickForce(KB)/FMAG
         END IF
         fTangential(1, KB) = -SCALE*F1
         IF (nFricDir .EQ. 2) fTangential(2, KB) = -SCALE*F2
C        Internal variables: dq = dlambda h, dlambda = |dslip|/|dg/dT|.
         IF (NQV .GT. 0 .AND. SCALE .EQ. 1.0D0) THEN
            DS = 0.0D0
            DO 90 I = 1, nDir
               DS = DS + dSlipFric(I, KB)**2
   90       CONTINUE
            DS = SQRT(DS)
            CALL @P@EV(FN*T(1), FN*T(2), FN, Q, P, W, 1)
            GT = SQRT(W(OFFDG + 1)**2 + W(OFFDG + 2)**2)
            DLAM = 0.0D0
            IF (GT .GT. 0.0D0) DLAM = DS/GT
            CALL @P@UQ(Q, Q0, W, DLAM, statev(1, NODE))
         END IF
  200 CONTINUE
      RETURN
      END
"""
